//! The structural checks behind [`Accel::validate`](crate::accel::Accel::validate): a walk from the
//! root that proves the traversal terminates, sees every live primitive once, and can trust each box.
//! O(n) time and memory; run by the factory in debug builds.

use super::{Node, LEAF_HARD_MAX, MAX_DEPTH};
use crate::accel::Primitives;

/// Checks the invariants listed in the module docs of [`super`].
pub(super) fn validate<P: Primitives + ?Sized>(
    nodes: &[Node],
    indices: &[u32],
    live: usize,
    prims: &P,
) -> Result<(), String> {
    let n = prims.len();
    if indices.len() != n {
        return Err(format!("built over {} primitives, queried with {n}", indices.len()));
    }
    let mut seen = vec![false; n];
    for &p in indices {
        let slot = seen.get_mut(p as usize).ok_or_else(|| format!("primitive index {p} out of range"))?;
        if std::mem::replace(slot, true) {
            return Err(format!("primitive {p} appears twice"));
        }
    }
    for &p in &indices[live.min(n)..] {
        let b = prims.bounds(p as usize);
        if !b.is_empty() && b.min.is_finite() && b.max.is_finite() {
            return Err(format!("primitive {p} has finite bounds but is not in the tree"));
        }
    }
    if nodes.is_empty() {
        return match live {
            0 => Ok(()),
            _ => Err(format!("{live} live primitives but no nodes")),
        };
    }
    check_tree(nodes, indices, live, prims)
}

/// Walks the tree depth first, first child before second, so leaves must tile `0..live` in order.
fn check_tree<P: Primitives + ?Sized>(nodes: &[Node], indices: &[u32], live: usize, prims: &P) -> Result<(), String> {
    let mut next_prim = 0usize;
    // (node, parent, depth)
    let mut stack = vec![(0usize, usize::MAX, 0usize)];
    let mut visited = 0usize;
    while let Some((i, parent, depth)) = stack.pop() {
        visited += 1;
        if visited > nodes.len() {
            return Err("a node is reachable twice".into());
        }
        let node = &nodes[i];
        let bounds = node.bounds();
        if parent != usize::MAX && !nodes[parent].bounds().contains(&bounds) {
            return Err(format!("node {i} is not inside its parent {parent}"));
        }
        if depth >= MAX_DEPTH {
            return Err(format!("node {i} at depth {depth} would overflow the traversal stack"));
        }
        if !node.is_leaf() {
            let second = node.offset as usize;
            if second <= i + 1 || second >= nodes.len() || i + 1 >= nodes.len() {
                return Err(format!("inner node {i} has second child {second}"));
            }
            // Pushed second child first, so the first child's subtree is checked (and its leaves
            // consumed) before the second's.
            stack.push((second, i, depth + 1));
            stack.push((i + 1, i, depth + 1));
            continue;
        }
        let (first, count) = (node.offset as usize, node.count as usize);
        if count > LEAF_HARD_MAX {
            return Err(format!("leaf {i} holds {count} primitives"));
        }
        if first != next_prim || first + count > live {
            return Err(format!("leaf {i} covers {first}..{} out of order", first + count));
        }
        next_prim += count;
        for &p in &indices[first..first + count] {
            if !bounds.contains(&prims.bounds(p as usize)) {
                return Err(format!("primitive {p} sticks out of leaf {i}"));
            }
        }
    }
    if visited != nodes.len() || next_prim != live {
        return Err(format!(
            "{visited} of {} nodes and {next_prim} of {live} live primitives are reachable",
            nodes.len()
        ));
    }
    Ok(())
}
