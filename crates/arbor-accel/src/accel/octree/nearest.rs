//! The closest-point query on the octree: depth first, a cell's non-empty octants sorted by their
//! distance to the point, the nearest visited first, the others pushed with their distances and
//! skipped when popped farther than the bound.
//!
//! Exact by the invariants of the module documentation (the leaves tile the root cube, and a leaf
//! references every live primitive that overlaps its cell grown by the margin, so every point of a
//! triangle lies in a closed cell that references it) and the slack argument of `accel/nearest.rs`: a
//! primitive met in a leaf is a candidate even when its point lies outside that cell. A primitive
//! referenced by several cells is weighed again in each, on the same numbers, which changes nothing.
//! Cost: at most seven pushes per level, so `1 + 7 * MAX_DEPTH` entries suffice.

use super::{child_box, split_point, Octree, MAX_DEPTH};
use crate::accel::nearest::{aabb_dist2, NearestSoFar};
use crate::accel::Primitives;
use crate::math::Aabb;

/// Deepest stack: each inner level pops one cell and pushes at most seven besides the one it goes on with.
const STACK: usize = 1 + 7 * MAX_DEPTH;

/// Offers `best` the primitives of the leaves within its bound, nearest cells first.
pub(super) fn walk<P: Primitives + ?Sized>(tree: &Octree, prims: &P, best: &mut NearestSoFar) {
    let (nodes, refs) = (&tree.nodes, &tree.refs);
    if nodes.is_empty() {
        return;
    }
    let p = best.point();
    let mut stack = [(0u32, Aabb::EMPTY, 0.0f64); STACK];
    stack[0] = (0, tree.root, aabb_dist2(p, &tree.root));
    let mut sp = 1;
    while sp > 0 {
        sp -= 1;
        let (at, cell, d2) = stack[sp];
        if d2 > best.bound() {
            continue;
        }
        let node = nodes[at as usize];
        if node.is_leaf() {
            for &prim in &refs[node.range()] {
                best.offer(prim, prims.closest_point(prim as usize, p));
            }
            continue;
        }
        // Non-empty octants within the bound, pushed farthest first so that the nearest is popped next.
        let mid = split_point(&cell);
        let base = sp;
        for k in 0..8 {
            let child = node.offset + k as u32;
            if nodes[child as usize].count == 0 {
                continue; // an empty leaf
            }
            let b = child_box(&cell, mid, k);
            let d = aabb_dist2(p, &b);
            if d > best.bound() {
                continue;
            }
            let mut j = sp;
            while j > base && stack[j - 1].2 < d {
                stack[j] = stack[j - 1];
                j -= 1;
            }
            stack[j] = (child, b, d);
            sp += 1;
        }
    }
}
