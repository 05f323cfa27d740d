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
//! type overrides it); the other builders, which share [`BuildPrim`], still ask `centroid`.
//!
//! On one thread the flat array is written directly, depth first. With more, nodes of at least
//! [`PARALLEL_THRESHOLD`] primitives become a temporary tree of boxed nodes whose halves are built with
//! `rayon::join`, smaller subtrees are written flat, and the whole is flattened at the end; since each
//! half owns a disjoint slice of the primitive array and every decision depends only on that slice, the
//! result is identical for any thread count.
//!
//! Robustness: primitives with empty or non-finite bounds never enter the tree; bin indices are computed
//! in single precision when the centroid extent and the bin scale are finite in it, else in double
//! precision, so centroids spanning the whole float range neither overflow nor produce NaN bins; areas
//! are always double precision.

use rayon::prelude::*;

use super::{BvhParams, Node, LEAF_HARD_MAX, MAX_BINS, MAX_SAH_DEPTH};
use crate::accel::Primitives;
use crate::math::{Aabb, Vec3};
use glam::Vec4;

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

/// One primitive as the SAH builder sees it, in 32 bytes: its bounds as two SIMD vectors (aligned
/// loads, one `minps`/`maxps` per union on x86_64). Their fourth lanes carry the low and the high 16
/// bits of the primitive's index as small whole numbers: exact in `f32`, harmless in any arithmetic
/// the builder does on whole vectors, and ignored by it.
#[derive(Debug, Clone, Copy)]
struct SahPrim {
    min: Vec4,
    max: Vec4,
}

impl SahPrim {
    #[inline(always)]
    fn new(bounds: &Aabb, index: u32) -> SahPrim {
        SahPrim { min: bounds.min.extend((index & 0xffff) as f32), max: bounds.max.extend((index >> 16) as f32) }
    }
    #[inline(always)]
    fn index(&self) -> u32 {
        self.min.w as u32 | (self.max.w as u32) << 16
    }
    /// The point the builder bins and splits by: the centre of the bounds, halved before adding so
    /// that boxes near the float range do not overflow (finite for finite bounds).
    #[inline(always)]
    fn centroid(&self) -> Vec4 {
        self.min * 0.5 + self.max * 0.5
    }
    /// [`SahPrim::centroid`] on axis `A` (the same operations, so the same value).
    #[inline(always)]
    fn centroid_on<const A: usize>(&self) -> f32 {
        0.5 * self.min[A] + 0.5 * self.max[A]
    }
}

/// A box being grown, in SIMD lanes. The builder's boxes are all finite, so the results are exactly
/// `Aabb::union`'s; the fourth lanes are ignored.
#[derive(Debug, Clone, Copy)]
struct BoxAcc {
    min: Vec4,
    max: Vec4,
}

impl BoxAcc {
    const EMPTY: BoxAcc = BoxAcc { min: Vec4::INFINITY, max: Vec4::NEG_INFINITY };

    #[inline(always)]
    fn add_prim(self, p: &SahPrim) -> BoxAcc {
        BoxAcc { min: self.min.min(p.min), max: self.max.max(p.max) }
    }
    #[inline(always)]
    fn add_point(self, p: Vec4) -> BoxAcc {
        BoxAcc { min: self.min.min(p), max: self.max.max(p) }
    }
    #[inline(always)]
    fn union(self, o: BoxAcc) -> BoxAcc {
        BoxAcc { min: self.min.min(o.min), max: self.max.max(o.max) }
    }
    #[inline(always)]
    fn aabb(self) -> Aabb {
        Aabb { min: self.min.truncate(), max: self.max.truncate() }
    }
    /// Surface area in double precision (`Aabb::area_f64`) of a box that is not empty.
    #[inline(always)]
    fn area(self) -> f64 {
        let e = self.max.truncate().as_dvec3() - self.min.truncate().as_dvec3();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }
}

/// What a node knows about its primitives before it is split: their bounds and their centroids'
/// bounds (from the parent's binning and partition, or the setup pass for the root).
#[derive(Debug, Clone, Copy)]
struct Boxes {
    bounds: BoxAcc,
    centroids: BoxAcc,
}

impl Boxes {
    const EMPTY: Boxes = Boxes { bounds: BoxAcc::EMPTY, centroids: BoxAcc::EMPTY };

    #[inline(always)]
    fn add(&mut self, p: &SahPrim) {
        self.bounds = self.bounds.add_prim(p);
        self.centroids = self.centroids.add_point(p.centroid());
    }
    fn union(self, o: Boxes) -> Boxes {
        Boxes { bounds: self.bounds.union(o.bounds), centroids: self.centroids.union(o.centroids) }
    }
    fn of(prims: &[SahPrim]) -> Boxes {
        let mut b = Boxes::EMPTY;
        for p in prims {
            b.add(p);
        }
        b
    }
}

/// How to split a node.
#[derive(Debug, Clone, Copy)]
enum Split {
    /// Primitives whose centroid falls in bins `0..=bin` go left; `left` and `right` bound each side.
    Bin { binner: Binner, bin: usize, left: BoxAcc, right: BoxAcc },
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

    #[inline(always)]
    fn bin(&self, c: f32) -> usize {
        // The minimum centroid lands in bin 0 and the maximum in the last bin (the ratio rounds to
        // `bins` or just below), so every candidate plane has primitives on both sides. The ratio is
        // never negative: converting through a signed type costs fewer instructions than `as usize`.
        let k = if self.single {
            ((c - self.min32) * self.scale32) as i32 as usize
        } else {
            ((c as f64 - self.min) * self.scale) as i64 as usize
        };
        k.min(self.bins - 1)
    }

    /// Whether `bin(c) <= bin` for a plane `bin < bins - 1`, without the conversion: the ratio truncates
    /// to at most `bin` exactly when it is below `bin + 1`.
    #[inline(always)]
    fn left_of(&self, c: f32, bin: usize) -> bool {
        debug_assert!(bin + 1 < self.bins);
        if self.single {
            (c - self.min32) * self.scale32 < (bin + 1) as f32
        } else {
            (c as f64 - self.min) * self.scale < (bin + 1) as f64
        }
    }
}

/// Builds the flat node array, the reordered primitive indices and the number of primitives in the tree.
pub(super) fn build_sah<P: Primitives + ?Sized>(prims: &P, params: &BvhParams) -> (Vec<Node>, Vec<u32>, usize) {
    let (mut live, dead, boxes) = sah_prims(prims);
    let mut nodes = Vec::new();
    if !live.is_empty() {
        // At most one node per primitive and one per leaf: pages reserved but never written cost
        // nothing, and shrinking in place copies nothing.
        nodes.reserve_exact(2 * live.len() - 1);
        if rayon::current_num_threads() == 1 {
            // No parallelism to gain: the whole tree by the flat writer, straight into its array.
            build_flat(&mut live, 0, boxes, 0, params, &mut Bins::new(), &mut nodes);
        } else {
            flatten(&build_node(&mut live, 0, boxes, 0, params), &mut nodes);
        }
        nodes.shrink_to_fit();
    }
    let indices = live.iter().map(SahPrim::index).chain(dead).collect();
    let live = live.len();
    (nodes, indices, live)
}

/// The SAH builder's view of every primitive that can be hit, in index order, the indices of those that
/// cannot (as [`split_live`]), and the root's boxes: one call to `bounds` per primitive, on chunks in
/// parallel (concatenated in order: the same result for any thread count).
fn sah_prims<P: Primitives + ?Sized>(prims: &P) -> (Vec<SahPrim>, Vec<u32>, Boxes) {
    const CHUNK: usize = 1 << 16;
    let n = prims.len();
    assert!(n <= u32::MAX as usize, "a BVH indexes at most 2^32 - 1 primitives");
    let chunk = |range: std::ops::Range<usize>| {
        let mut live = Vec::with_capacity(range.len());
        let mut dead = Vec::new();
        let mut boxes = Boxes::EMPTY;
        for i in range {
            let b = prims.bounds(i);
            if usable(&b) {
                let p = SahPrim::new(&b, i as u32);
                boxes.add(&p);
                live.push(p);
            } else {
                dead.push(i as u32);
            }
        }
        (live, dead, boxes)
    };
    if n <= CHUNK || rayon::current_num_threads() == 1 {
        return chunk(0..n);
    }
    let parts: Vec<_> =
        (0..n.div_ceil(CHUNK)).into_par_iter().map(|c| chunk(c * CHUNK..(n.min((c + 1) * CHUNK)))).collect();
    let mut live = Vec::with_capacity(parts.iter().map(|p| p.0.len()).sum());
    let mut dead = Vec::new();
    let mut boxes = Boxes::EMPTY;
    for (l, d, b) in parts {
        live.extend_from_slice(&l);
        dead.extend_from_slice(&d);
        boxes = boxes.union(b);
    }
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
    let Some(split) = find_split(prims, &boxes, depth, params, &mut Bins::new()) else {
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
    let Some(split) = find_split(prims, &boxes, depth, params, bins) else {
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
    if !usable(&bounds) {
        return None;
    }
    let c = prims.centroid(i);
    // Halves before adding: the plain midpoint overflows for boxes near the float range.
    let centroid = if c.is_finite() { c } else { 0.5 * bounds.min + 0.5 * bounds.max };
    Some(BuildPrim { bounds, centroid, index: i as u32 })
}

/// False for bounds that are empty or not finite: such a primitive can never be hit, and its box would
/// make every ancestor's box useless.
#[inline]
fn usable(bounds: &Aabb) -> bool {
    !bounds.is_empty() && bounds.min.is_finite() && bounds.max.is_finite()
}

/// A leaf over `count` primitives at `offset`.
pub(super) fn make_leaf(bounds: Aabb, offset: usize, count: usize) -> BuildNode {
    debug_assert!((1..=LEAF_HARD_MAX).contains(&count));
    BuildNode::Leaf { bounds, first: offset as u32, count: count as u16 }
}

/// The split to make, or `None` for a leaf.
fn find_split(prims: &[SahPrim], boxes: &Boxes, depth: usize, params: &BvhParams, bins: &mut Bins) -> Option<Split> {
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
    let best = best_bin(prims, &boxes.bounds, &binner, params, bins);
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

/// The cheapest plane found by [`best_bin`].
struct Best {
    /// The plane is after this bin (`bin < bins - 1`).
    bin: usize,
    /// Its SAH cost (infinite when no plane has primitives on both sides).
    cost: f64,
    /// Bounds of the primitives on each side.
    left: BoxAcc,
    right: BoxAcc,
}

// The bins a node fills are tracked in a `u32` mask.
const _: () = assert!(MAX_BINS <= 32);

/// Per-bin counts and bounds, kept empty between nodes (each node empties the bins it filled, so a
/// small node touches only the few bins its primitives fall in).
struct Bins {
    counts: [u32; MAX_BINS],
    boxes: [BoxAcc; MAX_BINS],
}

impl Bins {
    fn new() -> Box<Bins> {
        Box::new(Bins { counts: [0; MAX_BINS], boxes: [BoxAcc::EMPTY; MAX_BINS] })
    }

    /// Adds `prims` to the bins; returns the mask of the bins filled.
    fn fill<const A: usize>(&mut self, prims: &[SahPrim], binner: &Binner) -> u32 {
        let mut mask = 0u32;
        for p in prims {
            let k = binner.bin(p.centroid_on::<A>());
            self.counts[k] += 1;
            self.boxes[k] = self.boxes[k].add_prim(p);
            mask |= 1 << k;
        }
        mask
    }
}

/// The cheapest plane and its SAH cost. Only planes after non-empty bins are candidates: the plane
/// after an empty bin has the same two sides, hence the same cost, as the one after the last non-empty
/// bin before it, which comes first and wins the tie.
fn best_bin(prims: &[SahPrim], bounds: &BoxAcc, binner: &Binner, params: &BvhParams, bins: &mut Bins) -> Best {
    let mask = match binner.axis {
        0 => bins.fill::<0>(prims, binner),
        1 => bins.fill::<1>(prims, binner),
        _ => bins.fill::<2>(prims, binner),
    };
    // The non-empty bins in order.
    let mut used = [0u8; MAX_BINS];
    let mut m = 0;
    let mut rest = mask;
    while rest != 0 {
        used[m] = rest.trailing_zeros() as u8;
        rest &= rest - 1;
        m += 1;
    }
    let used = &used[..m];
    let (counts, boxes) = (&bins.counts, &bins.boxes);
    let block = params.leaf_block as u32;
    // Right-to-left sweep: count times area of everything right of each candidate plane.
    let mut right_cost = [0.0f64; MAX_BINS];
    let (mut b, mut c) = (BoxAcc::EMPTY, 0u32);
    for j in (1..m).rev() {
        let k = used[j] as usize;
        b = b.union(boxes[k]);
        c += counts[k];
        right_cost[j - 1] = c.div_ceil(block) as f64 * b.area();
    }
    // A node of zero area (primitives on a line) makes every plane cost the same; the first one
    // wins, and that is all a degenerate node needs.
    let area = bounds.area();
    let inv_area = if area > 0.0 { 1.0 / area } else { 0.0 };
    let (mut b, mut c) = (BoxAcc::EMPTY, 0u32);
    let mut best = Best { bin: 0, cost: f64::INFINITY, left: BoxAcc::EMPTY, right: BoxAcc::EMPTY };
    let mut best_j = 0;
    for j in 0..m.saturating_sub(1) {
        let k = used[j] as usize;
        b = b.union(boxes[k]);
        c += counts[k];
        let cost = params.traversal_cost as f64
            + params.intersection_cost as f64 * (c.div_ceil(block) as f64 * b.area() + right_cost[j]) * inv_area;
        if cost < best.cost {
            (best.bin, best.cost, best.left, best_j) = (k, cost, b, j);
        }
    }
    if best.cost.is_finite() {
        best.right = used[best_j + 1..].iter().fold(BoxAcc::EMPTY, |b, &k| b.union(boxes[k as usize]));
    }
    for &k in used {
        bins.counts[k as usize] = 0;
        bins.boxes[k as usize] = BoxAcc::EMPTY;
    }
    best
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
