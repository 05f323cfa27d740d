//! Queries for a batch of rays on the 8-wide tree, two rays at once: one step of each in turn
//! ([`Walker`]). A node visit is a chain of dependent loads and arithmetic that one ray cannot overlap
//! with its next visit, which depends on it, but the other ray's visit can fill that wait. Closest hits
//! ([`intersect_many_with`], whose walk is here; its coherent form's runs of rays go as packets,
//! `packet.rs`) and
//! any hits ([`super::occluded_many_with`], whose walk is in `any_hit.rs`) share the interleaving
//! ([`many`]). Each walk's node visit and pop are those of its single query, so each ray visits the same
//! nodes and gets the same answer as it would alone. The counted query stays one ray at a time.

use std::marker::PhantomData;

use super::dispatch::{run_with, Traversal};
use super::kernel::{Kernel, Lanes, NodeTest};
use super::leaves::{prepare, LeafRay, Leaves};
use super::visit::{new_stack, pop, visit, Stack};
use super::{Node8, Ref, Wide};
use crate::accel::closest::{trivially_misses, ClosestHit};
use crate::accel::{Hit, Primitives, TraversalCounts};
use crate::math::Ray;

/// Closest-hit queries for a batch of rays with `kernel`'s node test, `out[i]` for `rays[i]` in
/// `(0, t_max[i])`: the same hits as [`super::intersect_with`] ray by ray.
pub(in crate::accel::bvh) fn intersect_many_with<P: Primitives + ?Sized>(
    kernel: Kernel,
    wide: &Wide,
    indices: &[u32],
    prims: &P,
    rays: &[Ray],
    t_max: &[f32],
    out: &mut [Option<Hit>],
) {
    run_with(kernel, wide, indices, prims, Batch::<ClosestWalk>::new(rays, t_max, out))
}

/// The queries of a batch, each ray walked by a `W`.
pub(super) struct Batch<'a, W: Walker<'a>> {
    rays: &'a [Ray],
    t_max: &'a [f32],
    out: &'a mut [W::Out],
    walk: PhantomData<W>,
}

impl<'a, W: Walker<'a>> Batch<'a, W> {
    /// The batch `out[i]` = the answer for `rays[i]` in `(0, t_max[i])`.
    ///
    /// # Panics
    /// When `rays`, `t_max` and `out` differ in length.
    pub(super) fn new(rays: &'a [Ray], t_max: &'a [f32], out: &'a mut [W::Out]) -> Self {
        check_lengths(rays, t_max, out.len());
        Batch { rays, t_max, out, walk: PhantomData }
    }
}

/// Panics unless a batch's `rays`, `t_max` and `out_len` answers agree in length: every batch query
/// checks it before any ray is traced.
pub(super) fn check_lengths(rays: &[Ray], t_max: &[f32], out_len: usize) {
    assert!(rays.len() == t_max.len() && rays.len() == out_len, "a batch's rays, t_max and answers differ in length");
}

impl<'a, W: Walker<'a>> Traversal for Batch<'a, W> {
    type Out = ();

    fn empty(self) {
        self.out.fill(W::MISS);
    }

    #[inline(always)]
    fn run<L: Leaves, K: NodeTest>(self, kernel: K, nodes: &[Node8], leaves: &L, root: Ref) {
        many::<W, L, K>(kernel, nodes, leaves, root, self.rays, self.t_max, self.out)
    }
}

/// One ray's traversal as a state advanced one step at a time (a node visit, or a leaf and the pops
/// after it), so that [`many`] can interleave two.
pub(super) trait Walker<'r> {
    /// The query's answer.
    type Out: Copy;
    /// The answer of a ray that trivially misses.
    const MISS: Self::Out;
    /// The walk of `ray` from `root`.
    fn new(root: Ref, ray: &'r Ray, t_max: f32) -> Self;
    /// Starts over with another ray (in place: the stack is not moved).
    fn restart(&mut self, root: Ref, ray: &'r Ray, t_max: f32);
    /// One step.
    fn step<L: Leaves, K: NodeTest>(&mut self, kernel: K, nodes: &[Node8], leaves: &L);
    /// Whether the walk has its answer.
    fn done(&self) -> bool;
    /// The answer, once done.
    fn answer(&self) -> Self::Out;
}

/// The interleaved traversals of a batch, from `root`: two rays at once, in two named slots rather
/// than an array, so that both walks' state stays in registers (more rays at once would not fit them).
#[inline(always)]
pub(super) fn many<'r, W: Walker<'r>, L: Leaves, K: NodeTest>(
    kernel: K,
    nodes: &[Node8],
    leaves: &L,
    root: Ref,
    rays: &'r [Ray],
    t_max: &[f32],
    out: &mut [W::Out],
) {
    let mut next = 0;
    let Some(i) = next_ray::<W>(rays, t_max, out, &mut next) else { return };
    let (mut ia, mut a) = (i, W::new(root, &rays[i], t_max[i]));
    let Some(i) = next_ray::<W>(rays, t_max, out, &mut next) else {
        out[ia] = finish(&mut a, kernel, nodes, leaves);
        return;
    };
    let (mut ib, mut b) = (i, W::new(root, &rays[i], t_max[i]));
    // Both slots busy: step each in turn; a finished one takes the next ray, until none is left.
    loop {
        a.step(kernel, nodes, leaves);
        b.step(kernel, nodes, leaves);
        if a.done() && !refill(&mut a, &mut ia, root, rays, t_max, out, &mut next) {
            out[ib] = finish(&mut b, kernel, nodes, leaves);
            return;
        }
        if b.done() && !refill(&mut b, &mut ib, root, rays, t_max, out, &mut next) {
            out[ia] = finish(&mut a, kernel, nodes, leaves);
            return;
        }
    }
}

/// Hands finished walk `w`'s answer to `out[*i]` and starts it on the batch's next ray (its index into
/// `*i`); false when no ray is left.
#[inline(always)]
fn refill<'r, W: Walker<'r>>(
    w: &mut W,
    i: &mut usize,
    root: Ref,
    rays: &'r [Ray],
    t_max: &[f32],
    out: &mut [W::Out],
    next: &mut usize,
) -> bool {
    out[*i] = w.answer();
    let Some(k) = next_ray::<W>(rays, t_max, out, next) else { return false };
    *i = k;
    w.restart(root, &rays[k], t_max[k]);
    true
}

/// The index of the batch's next ray from `*next` on that needs a traversal; the rays skipped on the
/// way trivially miss and get [`Walker::MISS`].
#[inline(always)]
fn next_ray<'r, W: Walker<'r>>(rays: &[Ray], t_max: &[f32], out: &mut [W::Out], next: &mut usize) -> Option<usize> {
    while *next < rays.len() {
        let i = *next;
        *next += 1;
        if !trivially_misses(&rays[i], t_max[i]) {
            return Some(i);
        }
        out[i] = W::MISS;
    }
    None
}

/// Runs `w` to its end and returns its answer.
#[inline(always)]
fn finish<'r, W: Walker<'r>, L: Leaves, K: NodeTest>(w: &mut W, kernel: K, nodes: &[Node8], leaves: &L) -> W::Out {
    while !w.done() {
        w.step(kernel, nodes, leaves);
    }
    w.answer()
}

/// One ray's closest-hit traversal. The single query (`closest.rs`) is the same traversal run to its
/// end in one loop, which keeps its state in registers.
pub(super) struct ClosestWalk<'r> {
    lanes: Lanes,
    q: LeafRay<'r>,
    best: ClosestHit,
    stack: Stack,
    sp: usize,
    cur: Ref,
    done: bool,
}

impl<'r> Walker<'r> for ClosestWalk<'r> {
    type Out = Option<Hit>;
    const MISS: Option<Hit> = None;

    #[inline(always)]
    fn new(root: Ref, ray: &'r Ray, t_max: f32) -> Self {
        let (lanes, q) = prepare(ray);
        ClosestWalk { lanes, q, best: ClosestHit::new(t_max), stack: new_stack(), sp: 0, cur: root, done: false }
    }

    #[inline(always)]
    fn restart(&mut self, root: Ref, ray: &'r Ray, t_max: f32) {
        (self.lanes, self.q) = prepare(ray);
        self.best = ClosestHit::new(t_max);
        self.sp = 0;
        self.cur = root;
        self.done = false;
    }

    #[inline(always)]
    fn step<L: Leaves, K: NodeTest>(&mut self, kernel: K, nodes: &[Node8], leaves: &L) {
        if self.cur.count == 0 {
            let node = &nodes[self.cur.child as usize];
            if let Some(next) = visit::<L, K, true>(
                kernel,
                nodes,
                leaves,
                &self.lanes,
                node,
                self.best.t_far(),
                &mut self.stack,
                &mut self.sp,
            ) {
                self.cur = next;
                return;
            }
        } else {
            leaves.closest::<false>(self.cur, &mut self.q, &mut self.best, &mut TraversalCounts::default());
        }
        match pop(&self.stack, &mut self.sp, self.best.t_far()) {
            Some(next) => self.cur = next,
            None => self.done = true,
        }
    }

    #[inline(always)]
    fn done(&self) -> bool {
        self.done
    }

    #[inline(always)]
    fn answer(&self) -> Option<Hit> {
        self.best.hit()
    }
}
