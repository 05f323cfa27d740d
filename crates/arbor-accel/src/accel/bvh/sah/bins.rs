//! The binned part of the SAH builder: the map from centroids to bins ([`Binner`], in single precision
//! when it is exact enough, else double), the per-bin counts and boxes ([`Bins`]) and the sweep that
//! prices every candidate plane ([`best_bin`]).

use rayon::prelude::*;

use super::prim::{BoxAcc, SahPrim};
use crate::accel::bvh::{BvhParams, MAX_BINS};

/// Maps centroids to bins along one axis.
#[derive(Debug, Clone, Copy)]
pub(super) struct Binner {
    pub(super) axis: usize,
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
    #[inline]
    pub(super) fn new(axis: usize, min: f32, max: f32, bins: usize) -> Binner {
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
    pub(super) fn bin(&self, c: f32) -> usize {
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
    pub(super) fn left_of(&self, c: f32, bin: usize) -> bool {
        debug_assert!(bin + 1 < self.bins);
        if self.single {
            (c - self.min32) * self.scale32 < (bin + 1) as f32
        } else {
            (c as f64 - self.min) * self.scale < (bin + 1) as f64
        }
    }
}

/// The cheapest plane found by [`best_bin`].
pub(super) struct Best {
    /// The plane is after this bin (`bin < bins - 1`).
    pub(super) bin: usize,
    /// Its SAH cost (infinite when no plane has primitives on both sides).
    pub(super) cost: f64,
    /// Bounds of the primitives on each side.
    pub(super) left: BoxAcc,
    pub(super) right: BoxAcc,
}

/// Nodes of at least this many primitives are binned in parallel when the builder asks for it: the
/// top of the tree, whose few nodes would otherwise leave threads idle while one bins them all.
const PARALLEL_BINNING: usize = 1 << 15;
/// Primitives per parallel binning task.
const PARALLEL_BIN_CHUNK: usize = 1 << 13;

// The bins a node fills are tracked in a `u32` mask.
const _: () = assert!(MAX_BINS <= 32);

/// Per-bin counts and bounds, kept empty between nodes (each node empties the bins it filled, so a
/// small node touches only the few bins its primitives fall in).
pub(super) struct Bins {
    counts: [u32; MAX_BINS],
    boxes: [BoxAcc; MAX_BINS],
}

impl Bins {
    #[inline]
    pub(super) fn new() -> Box<Bins> {
        Box::new(Bins { counts: [0; MAX_BINS], boxes: [BoxAcc::EMPTY; MAX_BINS] })
    }

    /// Adds `prims` to the bins; returns the mask of the bins filled.
    fn fill(&mut self, prims: &[SahPrim], binner: &Binner) -> u32 {
        match binner.axis {
            0 => self.fill_on::<0>(prims, binner),
            1 => self.fill_on::<1>(prims, binner),
            _ => self.fill_on::<2>(prims, binner),
        }
    }

    /// [`Bins::fill`] on chunks of `prims` in parallel, each into bins of its own, merged at the end:
    /// counts add and boxes unite, so the bins are the same whatever the chunks and their order.
    fn fill_par(&mut self, prims: &[SahPrim], binner: &Binner) -> u32 {
        let (part, mask) = prims
            .par_chunks(PARALLEL_BIN_CHUNK)
            .map(|chunk| {
                let mut bins = Bins::new();
                let mask = bins.fill(chunk, binner);
                (bins, mask)
            })
            .reduce_with(|(mut a, ma), (b, mb)| {
                a.merge(&b, mb);
                (a, ma | mb)
            })
            .expect("a node to split has primitives");
        self.merge(&part, mask);
        mask
    }

    /// Adds bins `mask` of `other` to these.
    fn merge(&mut self, other: &Bins, mask: u32) {
        let mut rest = mask;
        while rest != 0 {
            let k = rest.trailing_zeros() as usize;
            rest &= rest - 1;
            self.counts[k] += other.counts[k];
            self.boxes[k] = self.boxes[k].union(other.boxes[k]);
        }
    }

    fn fill_on<const A: usize>(&mut self, prims: &[SahPrim], binner: &Binner) -> u32 {
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
///
/// `#[inline]` so that it may still be inlined into its one caller, `find_split`, in another module.
#[inline]
pub(super) fn best_bin(
    prims: &[SahPrim],
    bounds: &BoxAcc,
    binner: &Binner,
    params: &BvhParams,
    bins: &mut Bins,
    parallel: bool,
) -> Best {
    let mask = if parallel && prims.len() >= PARALLEL_BINNING {
        bins.fill_par(prims, binner)
    } else {
        bins.fill(prims, binner)
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
