//! Top-down median-split construction: each node splits its primitives' centroids at the median along
//! the longest axis of their bounds (the classic "equal counts" split; pbrt-v4's `SplitMethod::Middle`
//! and `EqualCounts`, tray_rust's median BVH).
//!
//! The median is found by selection (`select_nth_unstable_by`, O(n) expected), not by sorting, so the
//! build is O(n log n) overall. Ties between equal centroid coordinates are broken by primitive index:
//! the comparison is a total order, so the two halves are a pure function of the node's primitives and
//! the result is identical for any thread count (large nodes build their halves with `rayon::join`).
//!
//! Invariants: a node of more than `max_leaf_prims` primitives is always split into halves of
//! `floor(n/2)` and `ceil(n/2)`, so leaves hold between `ceil(max_leaf_prims/2)` and `max_leaf_prims`
//! primitives (fewer only when the whole set is smaller) and the depth is at most `ceil(log2 n)` ≤ 32,
//! far below [`super::MAX_DEPTH`]. Only [`BvhParams::max_leaf_prims`] is used; the SAH fields (bins and
//! costs) do not apply to this builder.

use std::cmp::Ordering;

use super::build::{finish, make_leaf, split_live, BuildNode, BuildPrim, PARALLEL_THRESHOLD};
use super::{BvhParams, Node};
use crate::accel::Primitives;
use crate::math::Aabb;

/// Builds the flat node array, the reordered primitive indices and the number of primitives in the tree.
pub(super) fn build_median<P: Primitives + ?Sized>(prims: &P, params: &BvhParams) -> (Vec<Node>, Vec<u32>, usize) {
    let (mut live, dead) = split_live(prims);
    let root = (!live.is_empty()).then(|| build_node(&mut live, 0, params.max_leaf_prims));
    finish(root.as_ref(), &live, &dead)
}

/// Builds the median-split subtree over `prims`, which sit at `offset` in the final index array, with
/// leaves of at most `max_leaf` (in `1..=LEAF_HARD_MAX`) primitives. Its height is at most
/// `ceil(log2(prims.len()))`; the bottom-up builder uses it to rebalance subtrees that are too deep.
pub(super) fn build_node(prims: &mut [BuildPrim], offset: usize, max_leaf: usize) -> BuildNode {
    let bounds = prims.iter().fold(Aabb::EMPTY, |b, p| b.union(p.bounds));
    let n = prims.len();
    if n <= max_leaf {
        return make_leaf(bounds, offset, n);
    }
    let axis = prims.iter().fold(Aabb::EMPTY, |b, p| b.grow(p.centroid)).longest_axis();
    let mid = n / 2;
    prims.select_nth_unstable_by(mid, |a, b| compare(a, b, axis));
    let (left, right) = prims.split_at_mut(mid);
    let (l, r) = if n >= PARALLEL_THRESHOLD {
        rayon::join(|| build_node(left, offset, max_leaf), || build_node(right, offset + mid, max_leaf))
    } else {
        (build_node(left, offset, max_leaf), build_node(right, offset + mid, max_leaf))
    };
    BuildNode::Inner { bounds, axis: axis as u8, children: Box::new([l, r]) }
}

/// Centroid coordinate on `axis`, then index: a total order (centroids are finite).
#[inline]
fn compare(a: &BuildPrim, b: &BuildPrim, axis: usize) -> Ordering {
    a.centroid[axis].total_cmp(&b.centroid[axis]).then(a.index.cmp(&b.index))
}
