//! The any-hit query (shadow rays) on the 8-wide tree: stops at the first hit, visits children in any
//! order, so it needs neither entry distances on its stack nor the closest-hit bookkeeping. A batch
//! ([`occluded_many_with`]) walks two rays at once as the closest-hit batch does (`batch.rs`), with the
//! same node visit ([`visit_any`]) and so the same nodes and answer per ray as the single query.

use std::mem::MaybeUninit;

use super::batch::{Batch, Walker};
use super::dispatch::{run_with, Traversal};
use super::kernel::{Kernel, Lanes, NodeTest};
use super::leaves::{prepare, LeafRay, Leaves};
use super::visit::STACK;
use super::{Node8, Ref, Wide};
use crate::accel::closest::trivially_misses;
use crate::accel::Primitives;
use crate::geometry::major_axis;
use crate::math::Ray;

/// Whether anything is hit in `(0, t_max)`, with `kernel`'s node test (the BVH passes the detected
/// one, tests compare them).
#[inline]
pub(in crate::accel::bvh) fn occluded_with<P: Primitives + ?Sized>(
    kernel: Kernel,
    wide: &Wide,
    indices: &[u32],
    prims: &P,
    ray: &Ray,
    t_max: f32,
) -> bool {
    run_with(kernel, wide, indices, prims, AnyHit { ray, t_max })
}

/// Any-hit queries for a batch of rays with `kernel`'s node test, `out[i]` for `rays[i]` in
/// `(0, t_max[i])`: the same answers as [`occluded_with`] ray by ray.
pub(in crate::accel::bvh) fn occluded_many_with<P: Primitives + ?Sized>(
    kernel: Kernel,
    wide: &Wide,
    indices: &[u32],
    prims: &P,
    rays: &[Ray],
    t_max: &[f32],
    out: &mut [bool],
) {
    run_with(kernel, wide, indices, prims, Batch::<AnyWalk>::new(rays, t_max, out))
}

/// The any-hit query of one ray.
struct AnyHit<'a> {
    ray: &'a Ray,
    t_max: f32,
}

impl Traversal for AnyHit<'_> {
    type Out = bool;

    fn empty(self) -> bool {
        false
    }

    #[inline(always)]
    fn run<L: Leaves, K: NodeTest>(self, kernel: K, nodes: &[Node8], leaves: &L, root: Ref) -> bool {
        !trivially_misses(self.ray, self.t_max) && any_hit(kernel, nodes, leaves, root, self.ray, self.t_max)
    }
}

/// The any-hit stack: children still to visit, in no order.
type AnyStack = [MaybeUninit<Ref>; STACK];

/// One node visit: tests `node`'s eight boxes against `[0, t_max]`, pushes every child hit but the
/// first and returns the first; `None` when no box is hit.
#[inline(always)]
fn visit_any<K: NodeTest>(
    kernel: K,
    lanes: &Lanes,
    node: &Node8,
    t_max: f32,
    stack: &mut AnyStack,
    sp: &mut usize,
) -> Option<Ref> {
    let (mut mask, _, _) = kernel.test(lanes, node, t_max);
    if mask == 0 {
        return None;
    }
    let first = mask.trailing_zeros() as usize;
    mask &= mask - 1;
    while mask != 0 {
        let l = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        stack[*sp] = MaybeUninit::new(Ref { child: node.child[l], count: node.count[l] });
        *sp += 1;
    }
    Some(Ref { child: node.child[first], count: node.count[first] })
}

/// The any-hit traversal from `root`.
#[inline(always)]
fn any_hit<L: Leaves, K: NodeTest>(kernel: K, nodes: &[Node8], leaves: &L, root: Ref, ray: &Ray, t_max: f32) -> bool {
    if root.count != 0 {
        // A tree that is one leaf: no box to test, so none of the node test's setup.
        return leaves.any(root, &mut LeafRay::new(ray, major_axis(ray.dir)), t_max);
    }
    let (lanes, mut q) = prepare(ray);
    let mut stack = [const { MaybeUninit::<Ref>::uninit() }; STACK];
    let mut sp = 0usize;
    let mut cur = root;
    loop {
        if cur.count == 0 {
            let node = &nodes[cur.child as usize];
            if let Some(next) = visit_any(kernel, &lanes, node, t_max, &mut stack, &mut sp) {
                cur = next;
                continue;
            }
        } else if leaves.any(cur, &mut q, t_max) {
            return true;
        }
        if sp == 0 {
            return false;
        }
        sp -= 1;
        // SAFETY: the entries below the stack pointer were written by `visit_any`.
        cur = unsafe { stack[sp].assume_init() };
    }
}

/// One ray's any-hit traversal as a state advanced one step at a time, for the batch.
struct AnyWalk<'r> {
    lanes: Lanes,
    q: LeafRay<'r>,
    t_max: f32,
    stack: AnyStack,
    sp: usize,
    cur: Ref,
    /// `Some(occluded)` once answered.
    answer: Option<bool>,
}

impl<'r> Walker<'r> for AnyWalk<'r> {
    type Out = bool;
    const MISS: bool = false;

    #[inline(always)]
    fn new(root: Ref, ray: &'r Ray, t_max: f32) -> Self {
        let (lanes, q) = prepare(ray);
        AnyWalk {
            lanes,
            q,
            t_max,
            stack: [const { MaybeUninit::<Ref>::uninit() }; STACK],
            sp: 0,
            cur: root,
            answer: None,
        }
    }

    #[inline(always)]
    fn restart(&mut self, root: Ref, ray: &'r Ray, t_max: f32) {
        (self.lanes, self.q) = prepare(ray);
        self.t_max = t_max;
        self.sp = 0;
        self.cur = root;
        self.answer = None;
    }

    #[inline(always)]
    fn step<L: Leaves, K: NodeTest>(&mut self, kernel: K, nodes: &[Node8], leaves: &L) {
        if self.cur.count == 0 {
            let node = &nodes[self.cur.child as usize];
            if let Some(next) = visit_any(kernel, &self.lanes, node, self.t_max, &mut self.stack, &mut self.sp) {
                self.cur = next;
                return;
            }
        } else if leaves.any(self.cur, &mut self.q, self.t_max) {
            self.answer = Some(true);
            return;
        }
        if self.sp == 0 {
            self.answer = Some(false);
            return;
        }
        self.sp -= 1;
        // SAFETY: the entries below the stack pointer were written by `visit_any`.
        self.cur = unsafe { self.stack[self.sp].assume_init() };
    }

    #[inline(always)]
    fn done(&self) -> bool {
        self.answer.is_some()
    }

    #[inline(always)]
    fn answer(&self) -> bool {
        self.answer == Some(true)
    }
}
