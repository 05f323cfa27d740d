//! The any-hit query (shadow rays) on the 8-wide tree: stops at the first hit, visits children in any
//! order, so it needs neither entry distances on its stack nor the closest-hit bookkeeping.

use std::mem::MaybeUninit;

use super::dispatch::{run_with, Traversal};
use super::kernel::{Kernel, Lanes, NodeTest};
use super::leaves::{LeafRay, Leaves};
use super::visit::STACK;
use super::{Node8, Ref, Wide};
use crate::accel::closest::trivially_misses;
use crate::accel::Primitives;
use crate::math::Ray;

/// Whether anything is hit in `(0, t_max)`.
#[inline]
pub(in crate::accel::bvh) fn occluded<P: Primitives + ?Sized>(
    wide: &Wide,
    indices: &[u32],
    prims: &P,
    ray: &Ray,
    t_max: f32,
) -> bool {
    occluded_with(Kernel::detect(), wide, indices, prims, ray, t_max)
}

/// [`occluded`] with the given kernel (tests compare the kernels).
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

/// The any-hit traversal from `root`.
#[inline(always)]
fn any_hit<L: Leaves, K: NodeTest>(kernel: K, nodes: &[Node8], leaves: &L, root: Ref, ray: &Ray, t_max: f32) -> bool {
    let lanes = Lanes::new(ray);
    let mut q = LeafRay::new(ray, lanes.major);
    let mut stack = [const { MaybeUninit::<Ref>::uninit() }; STACK];
    let mut sp = 0usize;
    let mut cur = root;
    loop {
        if cur.count == 0 {
            let node = &nodes[cur.child as usize];
            let (mut mask, _, _) = kernel.test(&lanes, node, t_max);
            if mask != 0 {
                let first = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                while mask != 0 {
                    let l = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    stack[sp] = MaybeUninit::new(Ref { child: node.child[l], count: node.count[l] });
                    sp += 1;
                }
                cur = Ref { child: node.child[first], count: node.count[first] };
                continue;
            }
        } else if leaves.any(cur, &mut q, t_max) {
            return true;
        }
        if sp == 0 {
            return false;
        }
        sp -= 1;
        // SAFETY: the entries below the stack pointer were written by the pushes above.
        cur = unsafe { stack[sp].assume_init() };
    }
}
