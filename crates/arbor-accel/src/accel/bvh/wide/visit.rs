//! One step of the closest-hit traversal, shared by the single query (`closest.rs`) and the batch
//! (`batch.rs`) so that both visit the same nodes: a node visit (test the eight boxes, push every child
//! hit but the nearest, go on with the nearest) and the pop of the next child still worth visiting.
//!
//! Children are pushed farthest first with their entry distance and slack; a popped entry is skipped
//! when `near > t_far + slack`, which is implied by failing its box test against the current `t_far`
//! (float addition is monotone), so the skip never drops a box that test would keep. A node at exactly
//! the best `t` is still visited. The stack lives in uninitialised memory so that a query does not pay
//! for clearing it.

use std::mem::MaybeUninit;

use super::super::MAX_DEPTH;
use super::kernel::{Lanes, NodeTest};
use super::leaves::Leaves;
use super::{Node8, Ref, WIDTH};

/// At most `WIDTH - 1` entries are pushed per level of the current path.
pub(super) const STACK: usize = (WIDTH - 1) * MAX_DEPTH + 1;

/// A pushed child: what it is, the distance at which the ray enters its box and that box's slack.
#[derive(Clone, Copy)]
pub(super) struct Entry {
    r: Ref,
    near: f32,
    slack: f32,
}

/// The traversal stack: `STACK` entries, of which those below the stack pointer are written.
pub(super) type Stack = [MaybeUninit<Entry>; STACK];

/// An empty stack (nothing written).
#[inline(always)]
pub(super) fn new_stack() -> Stack {
    [const { MaybeUninit::<Entry>::uninit() }; STACK]
}

/// Asks the cache for `lines` cache lines from `p`. Most of a query's stalls are the first loads of a
/// node or block: a child pushed now is fetched while its siblings are traversed. The child the query
/// goes on with is fetched too: its box test loads only its first three lines, and without the
/// prefetch the fourth (the child references) would be asked for only after that test, a second
/// trip to memory in a row.
#[inline(always)]
fn prefetch_lines(p: *const i8, lines: usize) {
    #[cfg(target_arch = "x86_64")]
    for k in 0..lines {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        // SAFETY: a prefetch never faults, whatever the address (so `p` needs no bounds check).
        unsafe { _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(64 * k)) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (p, lines);
}

/// Prefetches what `r` refers to: an inner node's four cache lines, or the first four of a leaf's data.
/// The address is selected without a branch: whether a child is a leaf is data that the branch
/// predictor cannot guess on incoherent rays.
#[inline(always)]
pub(super) fn prefetch<L: Leaves>(nodes: &[Node8], leaves: &L, r: Ref) {
    let node = nodes.as_ptr().wrapping_add(r.child as usize).cast::<i8>();
    prefetch_lines(std::hint::select_unpredictable(r.count == 0, node, leaves.address(r)), 4);
}

/// One node visit: tests `node`'s eight boxes against `[0, t_far]`, pushes every child hit but the
/// nearest (farthest deepest) and returns the nearest; `None` when no box is hit.
///
/// `MERGED` handles one and two children in one path without a branch on which. The batch takes it:
/// a mispredicted branch there throws away both rays' work in flight. A single query does not: the
/// always-written entry and second prefetch would lengthen its dependency chain.
#[allow(clippy::too_many_arguments)] // the traversal's state, kept in registers by the caller
#[inline(always)]
pub(super) fn visit<L: Leaves, K: NodeTest, const MERGED: bool>(
    kernel: K,
    nodes: &[Node8],
    leaves: &L,
    lanes: &Lanes,
    node: &Node8,
    t_far: f32,
    stack: &mut Stack,
    sp: &mut usize,
) -> Option<Ref> {
    let (mask, near, slack) = kernel.test(lanes, node, t_far);
    if mask == 0 {
        return None;
    }
    let first = mask.trailing_zeros() as usize;
    let rest = mask & (mask - 1);
    if !MERGED && rest == 0 {
        let cur = Ref { child: node.child[first], count: node.count[first] };
        prefetch(nodes, leaves, cur);
        return Some(cur);
    }
    if rest & rest.wrapping_sub(1) == 0 {
        // Two children, the common case: continue with the nearer, push the other. Merged, one child
        // takes this path too, without a branch: `second` is `first` and the entry written is not kept.
        let two = rest != 0;
        let second = if MERGED {
            std::hint::select_unpredictable(two, rest.trailing_zeros() as usize, first)
        } else {
            rest.trailing_zeros() as usize
        };
        let (go, push) = if near[second] < near[first] { (second, first) } else { (first, second) };
        let r = Ref { child: node.child[push], count: node.count[push] };
        stack[*sp] = MaybeUninit::new(Entry { r, near: near[push], slack: slack[push] });
        *sp += two as usize;
        prefetch(nodes, leaves, r);
        let cur = Ref { child: node.child[go], count: node.count[go] };
        prefetch(nodes, leaves, cur);
        return Some(cur);
    }
    // Three to eight children: push them all, sort the pushed entries so that the nearest is on top
    // (farthest deepest), and continue with the nearest.
    let base = *sp;
    let mut m = mask;
    while m != 0 {
        let l = m.trailing_zeros() as usize;
        m &= m - 1;
        let e = Entry { r: Ref { child: node.child[l], count: node.count[l] }, near: near[l], slack: slack[l] };
        // Insertion by decreasing `near`.
        let mut j = *sp;
        // SAFETY: `base..sp` were written by earlier rounds of this loop, and `j - 1` is in that range.
        while j > base && unsafe { stack[j - 1].assume_init_ref() }.near < e.near {
            stack[j] = stack[j - 1];
            j -= 1;
        }
        stack[j] = MaybeUninit::new(e);
        *sp += 1;
        prefetch(nodes, leaves, e.r);
    }
    *sp -= 1;
    // SAFETY: the loop above wrote at least three entries from `base` on; `*sp` is its last one.
    Some(unsafe { stack[*sp].assume_init() }.r)
}

/// Pops the nearest pushed child that may still hold a hit before `t_far`; `None` when none is left.
#[inline(always)]
pub(super) fn pop(stack: &Stack, sp: &mut usize, t_far: f32) -> Option<Ref> {
    while *sp > 0 {
        *sp -= 1;
        // SAFETY: the entries below the stack pointer were written by `visit`.
        let e = unsafe { stack[*sp].assume_init() };
        // Negated so that a NaN (which cannot arise here) would keep the entry, not drop it.
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        if !(e.near > t_far + e.slack) {
            return Some(e.r);
        }
    }
    None
}
