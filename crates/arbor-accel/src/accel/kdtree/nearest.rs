//! The closest-point query on the kd-tree: depth first, the child whose box is nearer the point first,
//! the other pushed with its box distance and skipped when popped farther than the bound.
//!
//! Exact by the invariant of the module documentation (a primitive is in every leaf whose closed box
//! holds a point of it) and the slack argument of `accel/nearest.rs`: a primitive met in a leaf is a
//! candidate even when its point lies outside that leaf. A primitive referenced by several leaves is
//! weighed again in each: its point and distance are the same numbers every time, so the answer does
//! not change. Cost: at most one push per level, so a stack of [`MAX_DEPTH`] entries suffices.

use super::{split_box, KdTree, MAX_DEPTH};
use crate::accel::nearest::{aabb_dist2, NearestSoFar};
use crate::accel::Primitives;
use crate::math::Aabb;

/// Offers `best` the primitives of the leaves within its bound, nearest leaves first.
pub(super) fn walk<P: Primitives + ?Sized>(tree: &KdTree, prims: &P, best: &mut NearestSoFar) {
    if tree.nodes.is_empty() {
        return;
    }
    let p = best.point();
    let mut stack = [(0u32, Aabb::EMPTY, 0.0f64); MAX_DEPTH];
    let mut sp = 0;
    let (mut at, mut cell) = (0usize, tree.bounds);
    if aabb_dist2(p, &cell) > best.bound() {
        return;
    }
    loop {
        let node = &tree.nodes[at];
        if !node.is_leaf() {
            let (below, above) = split_box(&cell, node.axis(), node.split());
            let (d_below, d_above) = (aabb_dist2(p, &below), aabb_dist2(p, &above));
            let ((near, near_box, d_near), far) = if d_below <= d_above {
                ((at + 1, below, d_below), (node.above(), above, d_above))
            } else {
                ((node.above(), above, d_above), (at + 1, below, d_below))
            };
            if far.2 <= best.bound() {
                stack[sp] = (far.0 as u32, far.1, far.2);
                sp += 1;
            }
            if d_near <= best.bound() {
                (at, cell) = (near, near_box);
                continue;
            }
        } else {
            for &prim in node.prims(&tree.refs) {
                best.offer(prim, prims.closest_point(prim as usize, p));
            }
        }
        loop {
            if sp == 0 {
                return;
            }
            sp -= 1;
            let (node, b, d2) = stack[sp];
            if d2 <= best.bound() {
                (at, cell) = (node as usize, b);
                break;
            }
        }
    }
}
