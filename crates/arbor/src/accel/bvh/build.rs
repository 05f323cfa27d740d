//! Top-down binned SAH construction (Wald 2007; pbrt-v4's `BVHAggregate::buildRecursive`).
//!
//! Each node bins its primitives' centroids into `bins` equal slabs along the axis of largest centroid
//! extent, sweeps the bins once from each side to get the cost of the `bins - 1` candidate planes,
//!
//! `cost(k) = traversal + intersection * (b(n_left) * area_left + b(n_right) * area_right) / area_node`,
//!
//! where `b(n) = ceil(n / leaf_block)` counts the blocks of triangles a leaf tests at once (Embree's
//! block-aware SAH; 1 primitive per block for other primitives), and partitions at the cheapest one; a
//! node of at most `max_leaf_prims` primitives becomes a leaf when that cost is not below
//! `intersection * b(n)`. Nodes whose centroids all coincide, and nodes below
//! [`MAX_SAH_DEPTH`], are split in the middle of their index range until they fit a leaf.
//!
//! The build works on a temporary tree of boxed nodes, then writes the flat array depth first. Large
//! nodes build their halves with `rayon::join`; since each half owns a disjoint slice of the primitive
//! array and every decision depends only on that slice, the result is identical for any thread count.
//!
//! Robustness: primitives with empty or non-finite bounds never enter the tree; bin indices are computed
//! in single precision when the centroid extent and the bin scale are finite in it, else in double
//! precision, so centroids spanning the whole float range neither overflow nor produce NaN bins; areas
//! are always double precision.

use rayon::prelude::*;

use super::{BvhParams, Node, LEAF_HARD_MAX, MAX_SAH_DEPTH};
use crate::accel::Primitives;
use crate::math::{Aabb, Vec3};
use glam::Vec3A;

/// Nodes with at least this many primitives build their two children in parallel.
pub(super) const PARALLEL_THRESHOLD: usize = 4096;

/// What the builder knows about one primitive.
#[derive(Debug, Clone, Copy)]
pub(super) struct BuildPrim {
    /// Bounds, finite and not empty.
    pub bounds: Aabb,
    /// The point the builders sort and split by.
    pub centroid: Vec3,
    /// The primitive's index in the input.
    pub index: u32,
}

/// The temporary tree, shared by every builder: leaves refer to ranges of the reordered primitives.
pub(super) enum BuildNode {
    Leaf {
        bounds: Aabb,
        first: u32,
        count: u16,
    },
    Inner {
        bounds: Aabb,
        axis: u8,
        children: Box<[BuildNode; 2]>,
    },
    /// A subtree already in the flat layout, second-child indices relative to its own first node (the
    /// SAH builder writes subtrees below the parallel threshold this way: no boxed node to allocate,
    /// walk and free for the bulk of the tree).
    Flat(Vec<Node>),
}

/// How to split a node.
#[derive(Debug, Clone, Copy)]
enum Split {
    /// Primitives whose centroid falls in bins `0..=bin` go left.
    Bin { binner: Binner, bin: usize },
    /// The first half of the index range goes left (coincident centroids, or too deep for SAH).
    Middle { axis: usize },
}

/// Maps centroids to bins along one axis.
#[derive(Debug, Clone, Copy)]
struct Binner {
    axis: usize,
    min: f64,
    scale: f64,
    /// The same map in single precision, used when the extent and the scale are finite in it (always,
    /// but for centroids spanning most of the float range): cheaper per primitive.
    min32: f32,
    scale32: f32,
    single: bool,
    bins: usize,
}

impl Binner {
    fn new(axis: usize, min: f32, max: f32, bins: usize) -> Binner {
        let scale32 = bins as f32 / (max - min);
        Binner {
            axis,
            min: min as f64,
            scale: bins as f64 / (max as f64 - min as f64),
            min32: min,
            scale32,
            single: (max - min).is_finite() && scale32.is_finite() && scale32 > 0.0,
            bins,
        }
    }

    #[inline]
    fn bin(&self, c: Vec3) -> usize {
        // The minimum centroid lands in bin 0 and the maximum in the last bin (the ratio rounds to
        // `bins` or just below), so every candidate plane has primitives on both sides.
        let k = if self.single {
            ((c[self.axis] - self.min32) * self.scale32) as usize
        } else {
            ((c[self.axis] as f64 - self.min) * self.scale) as usize
        };
        k.min(self.bins - 1)
    }
}

/// A box being grown, in SIMD lanes (glam's `Vec3A`: one `minps`/`maxps` per union on x86_64, where
/// `Aabb`'s `f32::min`/`max` take three NaN-aware instructions per axis). The builder's boxes are all
/// finite, so the results are exactly `Aabb::union`'s; this is most of the build's arithmetic.
#[derive(Debug, Clone, Copy)]
struct BoxAcc {
    min: Vec3A,
    max: Vec3A,
}

impl BoxAcc {
    const EMPTY: BoxAcc = BoxAcc { min: Vec3A::INFINITY, max: Vec3A::NEG_INFINITY };

    #[inline(always)]
    fn add_box(self, b: &Aabb) -> BoxAcc {
        BoxAcc { min: self.min.min(Vec3A::from(b.min)), max: self.max.max(Vec3A::from(b.max)) }
    }
    #[inline(always)]
    fn add_point(self, p: Vec3) -> BoxAcc {
        let p = Vec3A::from(p);
        BoxAcc { min: self.min.min(p), max: self.max.max(p) }
    }
    #[inline(always)]
    fn union(self, o: BoxAcc) -> BoxAcc {
        BoxAcc { min: self.min.min(o.min), max: self.max.max(o.max) }
    }
    #[inline(always)]
    fn aabb(self) -> Aabb {
        Aabb { min: self.min.into(), max: self.max.into() }
    }
}

/// Builds the flat node array, the reordered primitive indices and the number of primitives in the tree.
pub(super) fn build_sah<P: Primitives + ?Sized>(prims: &P, params: &BvhParams) -> (Vec<Node>, Vec<u32>, usize) {
    let (mut live, dead) = split_live(prims);
    let root = (!live.is_empty()).then(|| build_node(&mut live, 0, 0, params));
    finish(root.as_ref(), &live, &dead)
}

/// The builder's view of every primitive that can be hit, in index order, and the indices of those
/// that cannot (empty or non-finite bounds), which every builder keeps out of the tree.
pub(super) fn split_live<P: Primitives + ?Sized>(prims: &P) -> (Vec<BuildPrim>, Vec<u32>) {
    assert!(prims.len() <= u32::MAX as usize, "a BVH indexes at most 2^32 - 1 primitives");
    let live: Vec<BuildPrim> = (0..prims.len()).into_par_iter().filter_map(|i| build_prim(prims, i)).collect();
    // Rare: look for the primitives left out only when there are some.
    let dead = if live.len() < prims.len() {
        (0..prims.len()).filter(|&i| build_prim(prims, i).is_none()).map(|i| i as u32).collect()
    } else {
        Vec::new()
    };
    (live, dead)
}

/// The flat array of `root` (whose leaves refer to ranges of `live`, in that order), the index array
/// (`live`, then `dead`) and the number of live primitives: what [`super::Bvh::from_flat`] takes.
pub(super) fn finish(root: Option<&BuildNode>, live: &[BuildPrim], dead: &[u32]) -> (Vec<Node>, Vec<u32>, usize) {
    let mut nodes = Vec::new();
    if let Some(root) = root {
        // About two nodes per leaf of a few primitives; growing past it costs a copy, cheaper than
        // walking the tree to count.
        nodes.reserve(live.len() / 2);
        flatten(root, &mut nodes);
    }
    let indices = live.iter().map(|p| p.index).chain(dead.iter().copied()).collect();
    (nodes, indices, live.len())
}

/// The builder's view of primitive `i`, or `None` when its bounds are empty or not finite: such a
/// primitive can never be hit, and its box would make every ancestor's box useless.
fn build_prim<P: Primitives + ?Sized>(prims: &P, i: usize) -> Option<BuildPrim> {
    let bounds = prims.bounds(i);
    if bounds.is_empty() || !bounds.min.is_finite() || !bounds.max.is_finite() {
        return None;
    }
    let c = prims.centroid(i);
    // Halves before adding: the plain midpoint overflows for boxes near the float range.
    let centroid = if c.is_finite() { c } else { 0.5 * bounds.min + 0.5 * bounds.max };
    Some(BuildPrim { bounds, centroid, index: i as u32 })
}

/// Builds the subtree over `prims`, which sit at `offset` in the final index array.
fn build_node(prims: &mut [BuildPrim], offset: usize, depth: usize, params: &BvhParams) -> BuildNode {
    if prims.len() < PARALLEL_THRESHOLD {
        let mut out = Vec::with_capacity(prims.len() / 2);
        build_flat(prims, offset, depth, params, &mut out);
        return BuildNode::Flat(out);
    }
    let bounds = prims.iter().fold(BoxAcc::EMPTY, |b, p| b.add_box(&p.bounds)).aabb();
    let Some(split) = find_split(prims, &bounds, depth, params) else {
        return make_leaf(bounds, offset, prims.len());
    };
    let (mid, axis) = partition(prims, split);
    let (left, right) = prims.split_at_mut(mid);
    let (l, r) = if left.len() + right.len() >= PARALLEL_THRESHOLD {
        rayon::join(
            || build_node(left, offset, depth + 1, params),
            || build_node(right, offset + mid, depth + 1, params),
        )
    } else {
        (build_node(left, offset, depth + 1, params), build_node(right, offset + mid, depth + 1, params))
    };
    BuildNode::Inner { bounds, axis: axis as u8, children: Box::new([l, r]) }
}

/// [`build_node`] for a subtree built on one thread: appends its nodes depth first to `out` (second-child
/// indices relative to `out`'s start); returns the index of its root. Same decisions, same tree.
fn build_flat(prims: &mut [BuildPrim], offset: usize, depth: usize, params: &BvhParams, out: &mut Vec<Node>) -> u32 {
    let bounds = prims.iter().fold(BoxAcc::EMPTY, |b, p| b.add_box(&p.bounds)).aabb();
    let index = out.len() as u32;
    let Some(split) = find_split(prims, &bounds, depth, params) else {
        debug_assert!((1..=LEAF_HARD_MAX).contains(&prims.len()));
        out.push(Node::leaf(bounds, offset as u32, prims.len() as u16));
        return index;
    };
    let (mid, axis) = partition(prims, split);
    let (left, right) = prims.split_at_mut(mid);
    out.push(Node::inner(bounds, 0, axis as u8));
    build_flat(left, offset, depth + 1, params, out);
    let second = build_flat(right, offset + mid, depth + 1, params, out);
    out[index as usize].offset = second;
    index
}

/// A leaf over `count` primitives at `offset`.
pub(super) fn make_leaf(bounds: Aabb, offset: usize, count: usize) -> BuildNode {
    debug_assert!((1..=LEAF_HARD_MAX).contains(&count));
    BuildNode::Leaf { bounds, first: offset as u32, count: count as u16 }
}

/// The split to make, or `None` for a leaf.
fn find_split(prims: &[BuildPrim], bounds: &Aabb, depth: usize, params: &BvhParams) -> Option<Split> {
    let n = prims.len();
    if n == 1 {
        return None;
    }
    let cb = prims.iter().fold(BoxAcc::EMPTY, |b, p| b.add_point(p.centroid)).aabb();
    let axis = cb.longest_axis();
    if cb.max[axis] <= cb.min[axis] {
        // All centroids coincide: no plane separates them. Split only to keep leaves bounded.
        return (n > LEAF_HARD_MAX).then_some(Split::Middle { axis });
    }
    if depth >= MAX_SAH_DEPTH {
        return (n > params.max_leaf_prims).then_some(Split::Middle { axis });
    }
    let binner = Binner::new(axis, cb.min[axis], cb.max[axis], params.bins);
    let (bin, cost) = best_bin(prims, bounds, &binner, params);
    if !cost.is_finite() {
        // No plane has primitives on both sides; cannot happen while the centroid extent is positive,
        // but a range split keeps the recursion finite whatever the inputs.
        return Some(Split::Middle { axis });
    }
    let leaf_cost = params.intersection_cost as f64 * n.div_ceil(params.leaf_block) as f64;
    if n <= params.max_leaf_prims && cost >= leaf_cost {
        return None;
    }
    Some(Split::Bin { binner, bin })
}

/// The cheapest plane (after bin `k`, `k < bins - 1`) and its SAH cost.
fn best_bin(prims: &[BuildPrim], bounds: &Aabb, binner: &Binner, params: &BvhParams) -> (usize, f64) {
    let nb = binner.bins;
    let mut counts = [0usize; super::MAX_BINS];
    let mut boxes = [BoxAcc::EMPTY; super::MAX_BINS];
    for p in prims {
        let k = binner.bin(p.centroid);
        counts[k] += 1;
        boxes[k] = boxes[k].add_box(&p.bounds);
    }
    // Right-to-left sweep: count times area of everything right of each plane.
    let mut right_cost = [0.0f64; super::MAX_BINS];
    let (mut b, mut c) = (BoxAcc::EMPTY, 0usize);
    for k in (1..nb).rev() {
        b = b.union(boxes[k]);
        c += counts[k];
        right_cost[k - 1] = c.div_ceil(params.leaf_block) as f64 * b.aabb().area_f64();
    }
    // A node of zero area (primitives on a line) makes every plane cost the same; the first one with
    // primitives on both sides wins, and that is all a degenerate node needs.
    let area = bounds.area_f64();
    let inv_area = if area > 0.0 { 1.0 / area } else { 0.0 };
    let (mut b, mut c) = (BoxAcc::EMPTY, 0usize);
    let mut best = (0usize, f64::INFINITY);
    for k in 0..nb - 1 {
        b = b.union(boxes[k]);
        c += counts[k];
        if c == 0 || c == prims.len() {
            continue;
        }
        let cost = params.traversal_cost as f64
            + params.intersection_cost as f64
                * (c.div_ceil(params.leaf_block) as f64 * b.aabb().area_f64() + right_cost[k])
                * inv_area;
        if cost < best.1 {
            best = (k, cost);
        }
    }
    best
}

/// Reorders `prims` for `split`; returns the size of the left part (in `1..len`) and the split axis.
fn partition(prims: &mut [BuildPrim], split: Split) -> (usize, usize) {
    match split {
        Split::Middle { axis } => (prims.len() / 2, axis),
        Split::Bin { binner, bin } => {
            // Two-pointer partition: not stable, but a pure function of the slice, so deterministic.
            let (mut i, mut j) = (0, prims.len());
            while i < j {
                if binner.bin(prims[i].centroid) <= bin {
                    i += 1;
                } else {
                    j -= 1;
                    prims.swap(i, j);
                }
            }
            (i, binner.axis)
        }
    }
}

/// Appends `node`'s subtree depth first (first child right after its parent); returns its index.
fn flatten(node: &BuildNode, out: &mut Vec<Node>) -> u32 {
    let index = out.len();
    match node {
        BuildNode::Leaf { bounds, first, count } => out.push(Node::leaf(*bounds, *first, *count)),
        BuildNode::Inner { bounds, axis, children } => {
            out.push(Node::inner(*bounds, 0, *axis));
            flatten(&children[0], out);
            let second = flatten(&children[1], out);
            out[index] = Node::inner(*bounds, second, *axis);
        }
        BuildNode::Flat(nodes) => {
            let base = index as u32;
            out.extend(nodes.iter().map(|n| if n.is_leaf() { *n } else { Node { offset: n.offset + base, ..*n } }));
        }
    }
    index as u32
}
