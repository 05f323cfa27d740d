//! The octree's invariants (see the module docs of `octree`), checked from scratch: the shape of the
//! node array, the references of every leaf, and completeness: every live primitive is referenced by
//! every leaf whose (grown) cell it overlaps, which is what makes the traversal exact.
//!
//! Cost: about one build (each live primitive is pushed down the tree again), in parallel.

use rayon::prelude::*;

use super::build::references;
use super::{can_split, child_box, is_live, split_point, Octree, MAX_DEPTH};
use crate::accel::Primitives;
use crate::math::Aabb;

pub(super) fn validate<P: Primitives + ?Sized>(tree: &Octree, prims: &P) -> Result<(), String> {
    if tree.len != prims.len() {
        return Err(format!("built over {} primitives, queried with {}", tree.len, prims.len()));
    }
    let live: Vec<usize> = (0..prims.len()).filter(|&i| is_live(&prims.bounds(i))).collect();
    if tree.nodes.is_empty() {
        return match live.first() {
            Some(i) => Err(format!("empty tree, but primitive {i} can be hit")),
            None => Ok(()),
        };
    }
    let union = live.iter().fold(Aabb::EMPTY, |b, &i| b.union(prims.bounds(i)));
    if union != tree.bounds {
        return Err(format!("bounds {:?} differ from the live primitives' {union:?}", tree.bounds));
    }
    check_shape(tree)?;
    check_leaves(tree, prims)?;
    let first_error = live.par_iter().find_map_first(|&i| check_complete(tree, prims, i).err());
    first_error.map_or(Ok(()), Err)
}

/// Every node reached exactly once from the root, children after their parent, inner cells
/// splittable, depth bounded, and the leaves' ranges tiling the reference array.
fn check_shape(tree: &Octree) -> Result<(), String> {
    let nodes = &tree.nodes;
    let mut seen = vec![false; nodes.len()];
    let mut covered = vec![false; tree.refs.len()];
    let mut stack = vec![(0usize, tree.root, 0usize)];
    while let Some((i, cell, depth)) = stack.pop() {
        if std::mem::replace(&mut seen[i], true) {
            return Err(format!("node {i} is reached twice"));
        }
        if depth > MAX_DEPTH {
            return Err(format!("node {i} at depth {depth}, deeper than {MAX_DEPTH}"));
        }
        let n = &nodes[i];
        if n.is_leaf() {
            let r = n.range();
            if r.end > covered.len() {
                return Err(format!("leaf {i} refers past the end of the references"));
            }
            for slot in r {
                if std::mem::replace(&mut covered[slot], true) {
                    return Err(format!("reference slot {slot} belongs to two leaves"));
                }
            }
            continue;
        }
        let first = n.offset as usize;
        if first <= i || first + 8 > nodes.len() {
            return Err(format!("inner node {i} has children at {first}, out of order or range"));
        }
        let mid = split_point(&cell);
        if !can_split(&cell, mid) {
            return Err(format!("inner node {i} has a cell too small to tile with octants: {cell:?}"));
        }
        for k in 0..8 {
            stack.push((first + k, child_box(&cell, mid, k), depth + 1));
        }
    }
    if let Some(i) = seen.iter().position(|s| !s) {
        return Err(format!("node {i} is unreachable"));
    }
    if let Some(slot) = covered.iter().position(|c| !c) {
        return Err(format!("reference slot {slot} belongs to no leaf"));
    }
    Ok(())
}

/// Every reference names a live primitive that overlaps the leaf's cell, once, in ascending order.
fn check_leaves<P: Primitives + ?Sized>(tree: &Octree, prims: &P) -> Result<(), String> {
    let mut result = Ok(());
    tree.for_each_cell(|node, cell, _| {
        if result.is_err() || !node.is_leaf() {
            return;
        }
        let leaf = &tree.refs[node.range()];
        if leaf.windows(2).any(|w| w[0] >= w[1]) {
            result = Err(format!("leaf {cell:?} has references out of order or repeated"));
        } else if let Some(&i) = leaf.iter().find(|&&i| {
            let i = i as usize;
            i >= prims.len() || !is_live(&prims.bounds(i)) || !references(prims, i, cell, tree.margin)
        }) {
            result = Err(format!("leaf {cell:?} refers to primitive {i}, which is invalid or not in the cell"));
        }
    });
    result
}

/// Primitive `i` is in the root and referenced by every leaf whose cell it overlaps, and by one at least.
fn check_complete<P: Primitives + ?Sized>(tree: &Octree, prims: &P, i: usize) -> Result<(), String> {
    if !tree.root.contains(&prims.bounds(i)) {
        return Err(format!("primitive {i} sticks out of the root cell"));
    }
    let mut found = 0usize;
    let mut stack: Vec<(usize, Aabb)> = vec![(0, tree.root)];
    while let Some((n, cell)) = stack.pop() {
        let node = &tree.nodes[n];
        if node.is_leaf() {
            if tree.refs[node.range()].binary_search(&(i as u32)).is_err() {
                return Err(format!("primitive {i} overlaps the leaf {cell:?} but is not referenced there"));
            }
            found += 1;
            continue;
        }
        let mid = split_point(&cell);
        for k in 0..8 {
            let child = child_box(&cell, mid, k);
            if references(prims, i, &child, tree.margin) {
                stack.push((node.offset as usize + k, child));
            }
        }
    }
    if found == 0 {
        return Err(format!("primitive {i} is referenced by no leaf"));
    }
    Ok(())
}
