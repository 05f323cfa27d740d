//! PLOC, Parallel Locally-Ordered Clustering (Meister and Bittner 2018, "Parallel locally-ordered
//! clustering for bounding volume hierarchy construction", IEEE TVCG 24(3)).
//!
//! Primitives are sorted by the 63-bit Morton code of their centroid (21 bits per axis, over the
//! centroids' bounds; ties by index), which puts spatially close clusters close in the array. Then,
//! until one cluster is left: every cluster finds its nearest neighbour among the `radius` clusters on
//! either side, by the surface area of the merged box (ties by [`tie_key`], nearer first); mutual
//! nearest neighbours merge, the merged cluster taking the lower position; the array is compacted,
//! keeping the order. The globally least pair within reach is always mutual (the order on pairs is
//! total), so every iteration merges at least once.
//!
//! Cost: O(n log n) for the sort; each iteration is O(m · radius) for m clusters, run in parallel
//! (rayon), and merging plus compaction is one O(m) pass. On real meshes a large share of the clusters
//! merges in each iteration (42 iterations for the 69,451 triangles of the Stanford bunny), so the
//! iterations cost O(n · radius) overall in practice; adversarial
//! inputs (exponentially growing gaps) merge one pair per iteration, O(n² · radius), and build chains
//! that [`super::emit`] rebalances. The result does not depend on the thread count: the neighbour
//! search is a pure function of the cluster array, and the merge pass is sequential.

use rayon::prelude::*;

use super::{merge, Cluster};
use crate::accel::bvh::build::BuildPrim;
use crate::math::{Aabb, Vec3};

/// Clusters `prims` with PLOC; returns the arena (leaves `0..n`, root last).
pub(super) fn cluster(prims: &[BuildPrim], radius: usize) -> Vec<Cluster> {
    let n = prims.len();
    let mut arena: Vec<Cluster> = prims.iter().map(|p| Cluster::leaf(p.bounds)).collect();
    arena.reserve(n.saturating_sub(1));
    let mut clusters = morton_order(prims);
    let mut boxes: Vec<Aabb> = clusters.iter().map(|&c| arena[c as usize].bounds).collect();
    while clusters.len() > 1 {
        let nearest: Vec<usize> = (0..clusters.len()).into_par_iter().map(|i| nearest(&boxes, i, radius)).collect();
        let (mut next, mut next_boxes) = (Vec::with_capacity(clusters.len()), Vec::with_capacity(boxes.len()));
        for (i, &j) in nearest.iter().enumerate() {
            if nearest[j] != i {
                next.push(clusters[i]);
                next_boxes.push(boxes[i]);
            } else if i < j {
                let m = merge(&mut arena, clusters[i], clusters[j]);
                next.push(m);
                next_boxes.push(arena[m as usize].bounds);
            }
        }
        debug_assert!(next.len() < clusters.len(), "a PLOC iteration must merge");
        (clusters, boxes) = (next, next_boxes);
    }
    arena
}

/// The position within `radius` of `i` whose merged box with `i` has the least area, ties broken by
/// [`tie_key`].
fn nearest(boxes: &[Aabb], i: usize, radius: usize) -> usize {
    let (lo, hi) = (i.saturating_sub(radius), (i + radius + 1).min(boxes.len()));
    let mut best = (f64::INFINITY, usize::MAX);
    for j in (lo..hi).filter(|&j| j != i) {
        let a = boxes[i].union(boxes[j]).area_f64();
        if best.1 == usize::MAX || a < best.0 || (a == best.0 && tie_key(i, j) < tie_key(i, best.1)) {
            best = (a, j);
        }
    }
    best.1
}

/// Order among pairs of positions `{i, j}` of equal cost: nearer first, then, of the two candidates at
/// distance `d` from a position, the one making a pair whose lower position `p` has `p / d` even,
/// then the lower position. It depends on the pair only, so the globally least pair is still mutual;
/// and clusters with equal boxes (duplicate primitives) pair off as `{0, 1}, {2, 3}, ...`, halving
/// their number per iteration, where "ties to the lower position" would make `{0, 1}` the only
/// mutual pair and the clustering quadratic.
fn tie_key(i: usize, j: usize) -> (usize, usize, usize) {
    let (p, d) = (i.min(j), i.abs_diff(j));
    (d, (p / d) % 2, p)
}

/// Live primitive positions sorted by the Morton code of their centroids, ties by position.
fn morton_order(prims: &[BuildPrim]) -> Vec<u32> {
    let cb = prims.iter().fold(Aabb::EMPTY, |b, p| b.grow(p.centroid));
    let mut keyed: Vec<(u64, u32)> =
        prims.par_iter().enumerate().map(|(i, p)| (morton(p.centroid, &cb), i as u32)).collect();
    keyed.par_sort_unstable();
    keyed.into_iter().map(|(_, i)| i).collect()
}

/// The 63-bit Morton code of `c` in `cb`: 21 bits per axis, x in the highest bit of each triple.
/// Computed in double precision, so that centroid bounds spanning the float range do not overflow.
fn morton(c: Vec3, cb: &Aabb) -> u64 {
    const CELLS: f64 = (1u64 << 21) as f64;
    let mut code = 0u64;
    for axis in 0..3 {
        let (lo, hi) = (cb.min[axis] as f64, cb.max[axis] as f64);
        let q = if hi > lo { ((c[axis] as f64 - lo) / (hi - lo) * CELLS) as u64 } else { 0 };
        code |= spread(q.min((1 << 21) - 1)) << (2 - axis);
    }
    code
}

/// The low 21 bits of `x` moved to every third bit.
fn spread(x: u64) -> u64 {
    let mut x = x & 0x1f_ffff;
    x = (x | x << 32) & 0x1f_0000_0000_ffff;
    x = (x | x << 16) & 0x1f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}
