//! The closest-hit query of one ray on the 8-wide tree: nearest child first, a stack of the others.
//!
//! Exactness against brute force follows the binary traversal (`../traverse.rs`), whose argument holds
//! lane by lane: the node test is the same conservative box test (`kernel.rs`), a node at exactly the
//! best `t` is still visited and a popped child is skipped only when its box test would fail
//! (`visit.rs`), and leaves ask for hits up to the float above the best `t` and keep ties by lowest
//! primitive index (`leaves.rs`).

use super::dispatch::{run_with, Traversal};
use super::kernel::{Kernel, NodeTest};
use super::leaves::{prepare, LeafRay, Leaves};
use super::visit::{new_stack, pop, visit};
use super::{Node8, Ref, Wide};
use crate::accel::closest::{trivially_misses, ClosestHit};
use crate::accel::{Hit, Primitives, TraversalCounts};
use crate::geometry::major_axis;
use crate::math::Ray;

/// The closest hit in `(0, t_max)`, ties to the lowest primitive index, with `kernel`'s node test (the
/// BVH passes the detected one, tests compare them); with `COUNT`, the wide nodes visited and
/// primitives tested are added to `counts`.
#[inline]
pub(in crate::accel::bvh) fn intersect_with<P: Primitives + ?Sized, const COUNT: bool>(
    kernel: Kernel,
    wide: &Wide,
    indices: &[u32],
    prims: &P,
    ray: &Ray,
    t_max: f32,
    counts: &mut TraversalCounts,
) -> Option<Hit> {
    run_with(kernel, wide, indices, prims, Closest::<COUNT> { ray, t_max, counts })
}

/// The closest-hit query of one ray.
struct Closest<'a, const COUNT: bool> {
    ray: &'a Ray,
    t_max: f32,
    counts: &'a mut TraversalCounts,
}

impl<const COUNT: bool> Traversal for Closest<'_, COUNT> {
    type Out = Option<Hit>;

    fn empty(self) -> Option<Hit> {
        None
    }

    #[inline(always)]
    fn run<L: Leaves, K: NodeTest>(self, kernel: K, nodes: &[Node8], leaves: &L, root: Ref) -> Option<Hit> {
        if trivially_misses(self.ray, self.t_max) {
            return None;
        }
        query::<L, K, COUNT>(kernel, nodes, leaves, root, self.ray, self.t_max, self.counts)
    }
}

/// The closest-hit traversal from `root`.
#[inline(always)]
fn query<L: Leaves, K: NodeTest, const COUNT: bool>(
    kernel: K,
    nodes: &[Node8],
    leaves: &L,
    root: Ref,
    ray: &Ray,
    t_max: f32,
    counts: &mut TraversalCounts,
) -> Option<Hit> {
    let mut best = ClosestHit::new(t_max);
    if root.count != 0 {
        // A tree that is one leaf (a mesh of a few triangles, a scene's wall): no box to test, so none
        // of the node test's setup.
        let mut q = LeafRay::new(ray, major_axis(ray.dir));
        leaves.closest::<COUNT>(root, &mut q, &mut best, counts);
        return best.hit();
    }
    let (lanes, mut q) = prepare(ray);
    let mut stack = new_stack();
    let mut sp = 0usize;
    let mut cur = root;
    loop {
        if cur.count == 0 {
            if COUNT {
                counts.nodes += 1;
            }
            let node = &nodes[cur.child as usize];
            if let Some(next) =
                visit::<L, K, false>(kernel, nodes, leaves, &lanes, node, best.t_far(), &mut stack, &mut sp)
            {
                cur = next;
                continue;
            }
        } else {
            leaves.closest::<COUNT>(cur, &mut q, &mut best, counts);
        }
        match pop(&stack, &mut sp, best.t_far()) {
            Some(next) => cur = next,
            None => return best.hit(),
        }
    }
}
