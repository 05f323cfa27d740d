//! From the clustering's binary tree (one primitive per leaf) to the BVH's temporary tree, which
//! `build.rs` flattens into the shared node layout.
//!
//! 1. Leaf collapsing, bottom-up over the arena (children precede parents, so one forward pass): a
//!    subtree of at most `max_leaf` primitives becomes one leaf when `intersection * count * area` is
//!    not above its SAH cost as a tree (`traversal * area + children`), with the SAH build's default
//!    costs. The same pass records each subtree's height after collapsing.
//! 2. Emission, top-down: primitives are appended in depth-first leaf order, so every leaf is a
//!    contiguous range. Clustering can build chains as deep as the input is large; a subtree that would
//!    reach [`MAX_DEPTH`] is kept as it is down to depth [`MAX_SAH_DEPTH`] and rebuilt there with the
//!    median split, whose height is at most `ceil(log2 n)` ≤ 32, so every node stays above `MAX_DEPTH`
//!    (= `MAX_SAH_DEPTH` + 33) and the traversal stack cannot overflow. Only the primitives of those
//!    subtrees change hands; the rest of the tree is the clustering's.
//!
//! Cost: O(n) time and memory, plus O(k log k) for each rebalanced subtree of k primitives. Recursion
//! is bounded by `MAX_DEPTH`; walks of arbitrarily deep arena subtrees use explicit stacks.

use super::{Cluster, NO_CHILD};
use crate::accel::bvh::build::{make_leaf, BuildNode, BuildPrim};
use crate::accel::bvh::{median, BvhParams, MAX_DEPTH, MAX_SAH_DEPTH};
use crate::math::Aabb;

/// What the collapsing pass decided for each arena node.
struct Plan {
    /// Becomes one leaf (always true for the arena's leaves).
    collapse: Vec<bool>,
    /// Height of the subtree after collapsing (0 for a leaf).
    height: Vec<usize>,
}

/// The tree to flatten and the live primitives in the order its leaves refer to.
pub(super) fn emit(arena: &[Cluster], prims: &[BuildPrim], max_leaf: usize) -> (BuildNode, Vec<BuildPrim>) {
    let plan = plan(arena, max_leaf);
    let mut out = Emitter { arena, prims, plan: &plan, max_leaf, ordered: Vec::with_capacity(prims.len()) };
    let root = out.node(arena.len() - 1, 0);
    (root, out.ordered)
}

fn plan(arena: &[Cluster], max_leaf: usize) -> Plan {
    let d = BvhParams::default();
    let (ct, ci) = (d.traversal_cost as f64, d.intersection_cost as f64);
    let n = arena.len();
    let (mut count, mut cost) = (vec![1usize; n], vec![0.0f64; n]);
    let mut plan = Plan { collapse: vec![true; n], height: vec![0; n] };
    for (i, c) in arena.iter().enumerate() {
        let area = c.bounds.area_f64();
        if c.is_leaf() {
            cost[i] = ci * area;
            continue;
        }
        let [a, b] = c.kids.map(|k| k as usize);
        count[i] = count[a] + count[b];
        let as_tree = ct * area + cost[a] + cost[b];
        let as_leaf = ci * count[i] as f64 * area;
        plan.collapse[i] = count[i] <= max_leaf && as_leaf <= as_tree;
        cost[i] = if plan.collapse[i] { as_leaf } else { as_tree };
        plan.height[i] = if plan.collapse[i] { 0 } else { 1 + plan.height[a].max(plan.height[b]) };
    }
    plan
}

struct Emitter<'a> {
    arena: &'a [Cluster],
    prims: &'a [BuildPrim],
    plan: &'a Plan,
    max_leaf: usize,
    ordered: Vec<BuildPrim>,
}

impl Emitter<'_> {
    /// Emits arena node `i` at `depth`.
    fn node(&mut self, i: usize, depth: usize) -> BuildNode {
        let c = &self.arena[i];
        let offset = self.ordered.len();
        if self.plan.collapse[i] {
            self.collect(i);
            return make_leaf(c.bounds, offset, self.ordered.len() - offset);
        }
        if depth + self.plan.height[i] >= MAX_DEPTH && depth >= MAX_SAH_DEPTH {
            self.collect(i);
            return median::build_node(&mut self.ordered[offset..], offset, self.max_leaf);
        }
        let (axis, [a, b]) = self.order(c.kids);
        let l = self.node(a, depth + 1);
        let r = self.node(b, depth + 1);
        BuildNode::Inner { bounds: c.bounds, axis, children: Box::new([l, r]) }
    }

    /// The split axis of an inner node with children `kids`, and the children ordered along it: the
    /// traversal visits the first child first unless the ray goes down that axis.
    fn order(&self, kids: [u32; 2]) -> (u8, [usize; 2]) {
        let [a, b] = kids.map(|k| k as usize);
        let (axis, swap) = split_axis(&self.arena[a].bounds, &self.arena[b].bounds);
        (axis, if swap { [b, a] } else { [a, b] })
    }

    /// Appends the primitives of arena subtree `i`, first child first.
    fn collect(&mut self, i: usize) {
        let mut stack = vec![i];
        while let Some(j) = stack.pop() {
            let c = &self.arena[j];
            if c.kids[0] == NO_CHILD {
                self.ordered.push(self.prims[j]);
            } else {
                stack.push(c.kids[1] as usize);
                stack.push(c.kids[0] as usize);
            }
        }
    }
}

/// The axis along which the centres of boxes `a` and `b` are furthest apart, and whether `b`'s centre
/// is below `a`'s on it.
fn split_axis(a: &Aabb, b: &Aabb) -> (u8, bool) {
    let d = (b.min.as_dvec3() + b.max.as_dvec3()) - (a.min.as_dvec3() + a.max.as_dvec3());
    let e = d.abs();
    let axis = if e.x >= e.y && e.x >= e.z {
        0
    } else if e.y >= e.z {
        1
    } else {
        2
    };
    (axis as u8, d[axis] < 0.0)
}
