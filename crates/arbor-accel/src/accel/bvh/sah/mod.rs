//! Top-down binned SAH construction (Wald 2007; pbrt-v4's `BVHAggregate::buildRecursive`).
//!
//! Each node bins its primitives' centroids (the centres of their bounds) into `bins` equal slabs along
//! the axis of largest centroid extent, sweeps the non-empty bins once from each side to get the cost of
//! the candidate planes between them (a plane after an empty bin repeats an earlier plane's cost),
//!
//! `cost(k) = traversal + intersection * (b(n_left) * area_left + b(n_right) * area_right) / area_node`,
//!
//! where `b(n) = ceil(n / leaf_block)` counts the blocks of triangles a leaf tests at once (Embree's
//! block-aware SAH; 1 primitive per block for other primitives), and partitions at the cheapest one; a
//! node of at most `max_leaf_prims` primitives becomes a leaf when that cost is not below
//! `intersection * b(n)`. Nodes whose centroids all coincide, and nodes below
//! [`MAX_SAH_DEPTH`], are split in the middle of their index range until they fit a leaf.
//!
//! Two passes over a node's primitives: binning, then an in-place partition. A node's bounds and
//! centroid bounds come from its parent (the union of the bins on its side, and the centroid bounds the
//! partition grows on the way), and the root's from the setup pass that calls `Primitives::bounds` once
//! per primitive; each primitive is 32 bytes (bounds in two SIMD vectors, index in their fourth lanes).
//! The partition tests `ratio < bin + 1` rather than converting the bin ratio to an integer (the same
//! test: the bin is the ratio truncated). The bins stay empty between nodes: each node empties only the
//! bins it filled (a mask), so the many small nodes near the leaves cost little. The SAH builder splits
//! by the centres of the bounds, which is what `Primitives::centroid` returns by default (no primitive
//! type overrides it); the other builders, which share [`super::build::BuildPrim`], still ask `centroid`.
//!
//! On one thread the flat array is written directly, depth first. With more, nodes of at least
//! [`PARALLEL_THRESHOLD`] primitives become a temporary tree of boxed nodes whose halves are built with
//! `rayon::join`, smaller subtrees are written flat, and the whole is flattened at the end (its parts
//! in parallel too); since each half owns a disjoint slice of the primitive array and every decision
//! depends only on that slice, the result is identical for any thread count. The few nodes at the top
//! would leave threads idle while one bins them, so nodes of at least 2^15 primitives are binned in
//! parallel (`bins.rs`: per-chunk bins merged, the same bins); their partition stays serial, since a
//! parallel one would put the primitives in another order, and the order is part of the tree.
//!
//! Robustness: primitives with empty or non-finite bounds never enter the tree; bin indices are computed
//! in single precision when the centroid extent and the bin scale are finite in it, else in double
//! precision, so centroids spanning the whole float range neither overflow nor produce NaN bins; areas
//! are always double precision.

//!
//! Files: the primitive and box types in SIMD lanes (`prim.rs`), the bins and the cost sweep
//! (`bins.rs`); here the recursion (parallel and flat), the choice of split and the partition.

mod bins;
mod prim;

use std::mem::MaybeUninit;

use rayon::prelude::*;

use super::build::{flatten, make_leaf, one_thread, usable, BuildNode, PARALLEL_THRESHOLD};
use super::{BvhParams, Node, LEAF_HARD_MAX, MAX_SAH_DEPTH};
use crate::accel::Primitives;
use bins::{best_bin, Binner, Bins};
use prim::{BoxAcc, Boxes, SahPrim};

/// How to split a node.
#[derive(Debug, Clone, Copy)]
enum Split {
    /// Primitives whose centroid falls in bins `0..=bin` go left; `left` and `right` bound each side.
    Bin { binner: Binner, bin: usize, left: BoxAcc, right: BoxAcc },
    /// The first half of the index range goes left (coincident centroids, or too deep for SAH).
    Middle { axis: usize },
}

/// Builds the flat node array, the reordered primitive indices and the number of primitives in the tree.
pub(super) fn build_sah<P: Primitives + ?Sized>(prims: &P, params: &BvhParams) -> (Vec<Node>, Vec<u32>, usize) {
    let (mut live, dead, boxes) = sah_prims(prims);
    let mut nodes = Vec::new();
    if !live.is_empty() {
        // At most one node per primitive and one per leaf: pages reserved but never written cost
        // nothing, and shrinking in place copies nothing.
        nodes.reserve_exact(2 * live.len() - 1);
        // Both paths build the same tree.
        if one_thread() {
            // No parallelism to gain: the whole tree by the flat writer, straight into its array.
            build_flat(&mut live, 0, boxes, 0, params, &mut Bins::new(), &mut nodes);
        } else {
            flatten(&build_node(&mut live, 0, boxes, 0, params), &mut nodes);
        }
        nodes.shrink_to_fit();
    }
    let mut indices = Vec::with_capacity(prims.len());
    if one_thread() {
        indices.extend(live.iter().map(SahPrim::index));
    } else {
        live.par_iter().map(SahPrim::index).collect_into_vec(&mut indices);
    }
    indices.extend(dead);
    let live = live.len();
    (nodes, indices, live)
}

/// The SAH builder's view of every primitive that can be hit, in index order, the indices of those that
/// cannot (as [`split_live`](super::build::split_live)), and the root's boxes: one call to `bounds` per primitive, on chunks in
/// parallel, each writing its live primitives at the front of its own part of the final array (so
/// nothing is copied unless some primitive is dead: the same result for any thread count).
fn sah_prims<P: Primitives + ?Sized>(prims: &P) -> (Vec<SahPrim>, Vec<u32>, Boxes) {
    const CHUNK: usize = 1 << 14;
    let n = prims.len();
    assert!(n <= u32::MAX as usize, "a BVH indexes at most 2^32 - 1 primitives");
    let mut live = Vec::with_capacity(n);
    let chunk = |(c, out): (usize, &mut [MaybeUninit<SahPrim>])| {
        let (mut k, mut dead, mut boxes) = (0, Vec::new(), Boxes::EMPTY);
        for i in c * CHUNK..c * CHUNK + out.len() {
            let b = prims.bounds(i);
            if usable(&b) {
                let p = SahPrim::new(&b, i as u32);
                boxes.add(&p);
                out[k].write(p);
                k += 1;
            } else {
                dead.push(i as u32);
            }
        }
        (k, dead, boxes)
    };
    let spare = &mut live.spare_capacity_mut()[..n];
    let parts: Vec<(usize, Vec<u32>, Boxes)> = if one_thread() {
        spare.chunks_mut(CHUNK).enumerate().map(chunk).collect()
    } else {
        spare.par_chunks_mut(CHUNK).enumerate().map(chunk).collect()
    };
    let spare = live.spare_capacity_mut();
    let mut len = 0;
    for (c, &(k, _, _)) in parts.iter().enumerate() {
        if len != c * CHUNK {
            spare.copy_within(c * CHUNK..c * CHUNK + k, len);
        }
        len += k;
    }
    // SAFETY: each chunk wrote its first `k` entries, and they now sit, in chunk order, at `0..len`.
    unsafe { live.set_len(len) };
    let dead = parts.iter().flat_map(|p| p.1.iter().copied()).collect();
    let boxes = parts.iter().fold(Boxes::EMPTY, |b, p| b.union(p.2));
    (live, dead, boxes)
}

/// Builds the subtree over `prims` (whose boxes are `boxes`), which sit at `offset` in the final index
/// array: subtrees below [`PARALLEL_THRESHOLD`] by the flat writer, larger ones as inner nodes whose
/// halves are built with `rayon::join`.
fn build_node(prims: &mut [SahPrim], offset: usize, boxes: Boxes, depth: usize, params: &BvhParams) -> BuildNode {
    if prims.len() < PARALLEL_THRESHOLD {
        let mut out = Vec::with_capacity(2 * prims.len() - 1);
        build_flat(prims, offset, boxes, depth, params, &mut Bins::new(), &mut out);
        return BuildNode::Flat(out);
    }
    let bounds = boxes.bounds.aabb();
    let Some(split) = find_split(prims, &boxes, depth, params, &mut Bins::new(), true) else {
        return make_leaf(bounds, offset, prims.len());
    };
    let (mid, axis, l_boxes, r_boxes) = partition(prims, split);
    let (left, right) = prims.split_at_mut(mid);
    let (l, r) = rayon::join(
        || build_node(left, offset, l_boxes, depth + 1, params),
        || build_node(right, offset + mid, r_boxes, depth + 1, params),
    );
    BuildNode::Inner { bounds, axis: axis as u8, children: Box::new([l, r]) }
}

/// [`build_node`] for a subtree built on one thread: appends its nodes depth first to `out` (second-child
/// indices relative to `out`'s start); returns the index of its root. Same decisions, same tree.
fn build_flat(
    prims: &mut [SahPrim],
    offset: usize,
    boxes: Boxes,
    depth: usize,
    params: &BvhParams,
    bins: &mut Bins,
    out: &mut Vec<Node>,
) -> u32 {
    let bounds = boxes.bounds.aabb();
    let index = out.len() as u32;
    let Some(split) = find_split(prims, &boxes, depth, params, bins, false) else {
        debug_assert!((1..=LEAF_HARD_MAX).contains(&prims.len()));
        out.push(Node::leaf(bounds, offset as u32, prims.len() as u16));
        return index;
    };
    let (mid, axis, l_boxes, r_boxes) = partition(prims, split);
    let (left, right) = prims.split_at_mut(mid);
    out.push(Node::inner(bounds, 0, axis as u8));
    build_flat(left, offset, l_boxes, depth + 1, params, bins, out);
    let second = build_flat(right, offset + mid, r_boxes, depth + 1, params, bins, out);
    out[index as usize].offset = second;
    index
}

/// The split to make, or `None` for a leaf; `parallel`: a large node may be binned in parallel.
fn find_split(
    prims: &[SahPrim],
    boxes: &Boxes,
    depth: usize,
    params: &BvhParams,
    bins: &mut Bins,
    parallel: bool,
) -> Option<Split> {
    let n = prims.len();
    if n == 1 {
        return None;
    }
    let cb = boxes.centroids.aabb();
    let axis = cb.longest_axis();
    if cb.max[axis] <= cb.min[axis] {
        // All centroids coincide: no plane separates them. Split only to keep leaves bounded.
        return (n > LEAF_HARD_MAX).then_some(Split::Middle { axis });
    }
    if depth >= MAX_SAH_DEPTH {
        return (n > params.max_leaf_prims).then_some(Split::Middle { axis });
    }
    let binner = Binner::new(axis, cb.min[axis], cb.max[axis], params.bins);
    let best = best_bin(prims, &boxes.bounds, &binner, params, bins, parallel);
    if !best.cost.is_finite() {
        // No plane has primitives on both sides; cannot happen while the centroid extent is positive,
        // but a range split keeps the recursion finite whatever the inputs.
        return Some(Split::Middle { axis });
    }
    let leaf_cost = params.intersection_cost as f64 * n.div_ceil(params.leaf_block) as f64;
    if n <= params.max_leaf_prims && best.cost >= leaf_cost {
        return None;
    }
    Some(Split::Bin { binner, bin: best.bin, left: best.left, right: best.right })
}

/// Reorders `prims` for `split`; returns the size of the left part (in `1..len`), the split axis and
/// the boxes of both parts.
fn partition(prims: &mut [SahPrim], split: Split) -> (usize, usize, Boxes, Boxes) {
    match split {
        Split::Middle { axis } => {
            let mid = prims.len() / 2;
            (mid, axis, Boxes::of(&prims[..mid]), Boxes::of(&prims[mid..]))
        }
        Split::Bin { binner, bin, left, right } => {
            let (mid, l, r) = match binner.axis {
                0 => partition_bin::<0>(prims, &binner, bin),
                1 => partition_bin::<1>(prims, &binner, bin),
                _ => partition_bin::<2>(prims, &binner, bin),
            };
            (mid, binner.axis, Boxes { bounds: left, centroids: l }, Boxes { bounds: right, centroids: r })
        }
    }
}

/// Hoare partition by bin (not stable, but a pure function of the slice, so deterministic), growing
/// the centroid bounds of both sides on the way; returns the size of the left side and those bounds.
fn partition_bin<const A: usize>(prims: &mut [SahPrim], binner: &Binner, bin: usize) -> (usize, BoxAcc, BoxAcc) {
    let goes_left = |p: &SahPrim| binner.left_of(p.centroid_on::<A>(), bin);
    let (mut i, mut j) = (0, prims.len());
    let (mut l, mut r) = (BoxAcc::EMPTY, BoxAcc::EMPTY);
    loop {
        while i < j && goes_left(&prims[i]) {
            l = l.add_point(prims[i].centroid());
            i += 1;
        }
        while i < j && !goes_left(&prims[j - 1]) {
            r = r.add_point(prims[j - 1].centroid());
            j -= 1;
        }
        if i == j {
            return (i, l, r);
        }
        // `prims[i]` goes right and `prims[j - 1]` left.
        prims.swap(i, j - 1);
        l = l.add_point(prims[i].centroid());
        r = r.add_point(prims[j - 1].centroid());
        i += 1;
        j -= 1;
    }
}
