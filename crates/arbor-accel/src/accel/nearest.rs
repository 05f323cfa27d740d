//! Closest-point queries: the primitive nearest to a point, the point of it nearest, and their squared
//! distance. The bookkeeping every structure shares ([`NearestSoFar`]), so that all of them return what
//! brute force returns, and the refusal for primitives that cannot answer.
//!
//! The answer, for query point `p` and bound `max_distance`: among the primitives whose closest point
//! `q` ([`crate::accel::Primitives::closest_point`], in `f64`) has a squared distance `d² = |q - p|²` that is a number
//! and at most `max_distance²`, the one with the smallest `d²`, ties to the lowest primitive index.
//! `d²` is computed here, by one function ([`dist2`]), whichever structure meets the primitive, so a
//! tie is decided on the same numbers everywhere; the primitive's point comes from one function too
//! (a triangle's from `geometry::closest_point_on_triangle_f64`, whether it is read from the mesh or
//! from a BVH leaf's copy of its corners). Triangles with a non-finite corner are never the answer.
//!
//! Algorithm: every structure is walked depth first, nearest child first, and a node or cell is skipped
//! when the squared distance from `p` to its box ([`box_dist2`]) exceeds [`NearestSoFar::bound`], which
//! shrinks as candidates are found (Samet's ordered depth-first nearest-neighbour search).
//!
//! Why skipping is exact:
//! - BVH: a primitive's point lies in its own bounds (the trait asks it; triangles clamp it into their
//!   corners' box), so in every box above it, and [`box_dist2`] and [`dist2`] are the same monotone
//!   float expression of per-axis gaps, each no larger for the box: the computed box distance never
//!   exceeds the computed candidate distance, and the bound is the best `d²` itself. A node at exactly
//!   the best distance is visited, so a tie there is still weighed by index.
//! - Kd-tree and octree: a leaf references a primitive that merely overlaps its cell, and a primitive's
//!   point may lie outside that cell (even in a cell that does not reference it), so a candidate is
//!   valid wherever it is met. The invariant that makes cell pruning exact: every point of a triangle
//!   lies in some (closed) cell that references it (`kdtree` and `octree` state how their builds
//!   guarantee it). The computed point is within [`slack`] of a true point of the triangle (a convex
//!   combination of the corners up to rounding, far below `2^-40` of the largest coordinate), which lies
//!   in such a cell, so that cell is at most `d + slack` away; the bound is `(d + slack)²`, widened by a
//!   relative `2^-40` for the rounding of the distances themselves. A looser bound costs visits only.
//! - Brute force tests every primitive in index order.
//!
//! Cost: O(log n) node visits for a point near a well-built structure's surface, up to every node for
//! points far from a large flat mesh (many boxes at nearly the same distance); each visit is a few box
//! distances in `f64`. Nothing is allocated: the stacks have fixed sizes (each structure's depth limit).

use std::fmt;

use super::AccelKind;
use crate::math::{Aabb, DVec3};

/// The point of one primitive closest to a query point, before its index and distance are known.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PrimPoint {
    /// The point, which must lie inside the primitive's bounds ([`super::Primitives::bounds`]).
    pub point: DVec3,
    /// First surface parameter (for triangles, the barycentric weight of vertex 1).
    pub u: f64,
    /// Second surface parameter (the weight of vertex 2).
    pub v: f64,
}

/// The answer of a closest-point query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nearest {
    /// Index of the nearest primitive.
    pub prim: u32,
    /// Its point nearest to the query point.
    pub point: DVec3,
    /// The squared distance between the two.
    pub dist2: f64,
    /// First surface parameter of the point, see [`PrimPoint`].
    pub u: f64,
    /// Second surface parameter of the point, see [`PrimPoint`].
    pub v: f64,
}

impl Nearest {
    /// The distance to the query point.
    pub fn distance(&self) -> f64 {
        self.dist2.sqrt()
    }
}

/// Why a structure cannot answer closest-point queries: its primitives do not implement
/// [`super::Primitives::closest_point`] (a renderer's spheres and instances, say). Triangle meshes do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ClosestPointUnsupported {
    /// The structure asked.
    pub kind: AccelKind,
}

impl fmt::Display for ClosestPointUnsupported {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}: closest-point queries need primitives that give their closest point (triangle meshes do; these do not)",
            self.kind
        )
    }
}

impl std::error::Error for ClosestPointUnsupported {}

/// The squared length of `d`, the one expression every candidate and box distance goes through.
#[inline(always)]
pub(crate) fn dist2(d: DVec3) -> f64 {
    d.x * d.x + d.y * d.y + d.z * d.z
}

/// The squared distance from `p` to the box `min..max` (0 inside it; infinite for the inverted empty
/// box, whose gaps are infinite).
#[inline(always)]
pub(crate) fn box_dist2(p: DVec3, min: DVec3, max: DVec3) -> f64 {
    dist2((min - p).max(p - max).max(DVec3::ZERO))
}

/// [`box_dist2`] of an [`Aabb`].
#[inline(always)]
pub(crate) fn aabb_dist2(p: DVec3, b: &Aabb) -> f64 {
    box_dist2(p, b.min.as_dvec3(), b.max.as_dvec3())
}

/// The absolute slack of cell pruning for primitives inside `bounds` (see the module documentation):
/// `2^-40` of the largest coordinate, at least the smallest normal `f64`.
pub(crate) fn slack(bounds: &Aabb) -> f64 {
    let m = bounds.min.abs().max(bounds.max.abs()).max_element() as f64;
    (m * 2f64.powi(-40)).max(f64::MIN_POSITIVE)
}

/// Runs a closest-point query: `walk` offers candidates to the bookkeeping of point `p`, bound
/// `max_dist2` and pruning slack `slack` (0 for structures whose boxes hold their primitives' points,
/// [`slack`] for cell structures). Nothing is walked for a non-finite point or a bound that is NaN or
/// negative: no primitive can be the answer.
#[inline]
pub(crate) fn query(p: DVec3, max_dist2: f64, slack: f64, walk: impl FnOnce(&mut NearestSoFar)) -> Option<Nearest> {
    if !p.is_finite() || max_dist2.is_nan() || max_dist2 < 0.0 {
        return None;
    }
    let mut best = NearestSoFar::new(p, max_dist2, slack);
    walk(&mut best);
    best.best()
}

/// The best candidate so far of one query, and the bound boxes are pruned against.
#[derive(Debug, Clone, Copy)]
pub(crate) struct NearestSoFar {
    p: DVec3,
    best: Option<Nearest>,
    /// Candidates farther than this (squared) are refused.
    limit: f64,
    /// Boxes farther than this (squared) are skipped.
    bound: f64,
    slack: f64,
}

impl NearestSoFar {
    /// No candidate yet for point `p`, within squared distance `max_dist2`, pruning with `slack`.
    #[inline]
    pub(crate) fn new(p: DVec3, max_dist2: f64, slack: f64) -> Self {
        let mut n = NearestSoFar { p, best: None, limit: max_dist2, bound: max_dist2, slack };
        n.bound = n.widened(max_dist2);
        n
    }

    /// The query point.
    #[inline(always)]
    pub(crate) fn point(&self) -> DVec3 {
        self.p
    }

    /// Boxes whose squared distance exceeds this cannot hold a better candidate.
    #[inline(always)]
    pub(crate) fn bound(&self) -> f64 {
        self.bound
    }

    fn widened(&self, d2: f64) -> f64 {
        if self.slack == 0.0 {
            return d2;
        }
        const REL: f64 = 1.0 + 1.0 / (1u64 << 40) as f64;
        let d = d2.sqrt() * REL + self.slack;
        d * d * REL
    }

    /// Weighs primitive `prim`'s point `pp` (none: the primitive cannot be the answer).
    #[inline(always)]
    pub(crate) fn offer(&mut self, prim: u32, pp: Option<PrimPoint>) {
        let Some(pp) = pp else { return };
        let d2 = dist2(pp.point - self.p);
        if d2.is_nan() || d2 > self.limit {
            return;
        }
        if let Some(b) = &self.best {
            if d2 > b.dist2 || (d2 == b.dist2 && prim >= b.prim) {
                return;
            }
        }
        self.best = Some(Nearest { prim, point: pp.point, dist2: d2, u: pp.u, v: pp.v });
        self.limit = d2;
        self.bound = self.widened(d2);
    }

    /// The answer.
    #[inline(always)]
    pub(crate) fn best(&self) -> Option<Nearest> {
        self.best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pp(x: f64) -> Option<PrimPoint> {
        Some(PrimPoint { point: DVec3::new(x, 0.0, 0.0), u: 0.0, v: 0.0 })
    }

    #[test]
    fn nearest_keeps_the_smaller_distance_then_the_lower_index() {
        let mut n = NearestSoFar::new(DVec3::ZERO, f64::INFINITY, 0.0);
        assert_eq!((n.best(), n.bound()), (None, f64::INFINITY));
        n.offer(5, pp(3.0));
        assert_eq!((n.best().unwrap().prim, n.best().unwrap().dist2, n.bound()), (5, 9.0, 9.0));
        n.offer(2, pp(-3.0));
        assert_eq!(n.best().unwrap().prim, 2, "a tie goes to the lower index");
        n.offer(7, pp(3.0));
        assert_eq!(n.best().unwrap().prim, 2, "a tie with a higher index is refused");
        n.offer(9, pp(2.5));
        assert_eq!(n.best().unwrap().prim, 9, "a smaller distance wins whatever its index");
        n.offer(0, pp(f64::NAN));
        n.offer(0, None);
        assert_eq!(n.best().unwrap().prim, 9, "no point, or a NaN distance, is no candidate");
    }

    #[test]
    fn nearest_refuses_candidates_beyond_the_bound_and_widens_cell_bounds() {
        let mut n = NearestSoFar::new(DVec3::ZERO, 4.0, 0.0);
        n.offer(0, pp(2.5));
        assert_eq!(n.best(), None);
        n.offer(1, pp(2.0));
        assert_eq!(n.best().unwrap().dist2, 4.0, "the bound is inclusive");
        let mut cells = NearestSoFar::new(DVec3::ZERO, f64::INFINITY, 0.5);
        cells.offer(0, pp(2.0));
        assert!(cells.bound() >= 6.25 && cells.bound() < 6.25 * (1.0 + 1e-11), "{}", cells.bound());
    }

    #[test]
    fn box_distance_is_zero_inside_and_the_gap_outside() {
        let b = Aabb::new(crate::math::Vec3::ZERO, crate::math::Vec3::ONE);
        assert_eq!(aabb_dist2(DVec3::splat(0.5), &b), 0.0);
        assert_eq!(aabb_dist2(DVec3::new(3.0, -2.0, 0.5), &b), 4.0 + 4.0);
        assert_eq!(aabb_dist2(DVec3::ZERO, &Aabb::EMPTY), f64::INFINITY);
    }

    #[test]
    fn nearest_query_walks_nothing_for_a_nan_point_or_bound() {
        let offer = |n: &mut NearestSoFar| n.offer(0, pp(1.0));
        assert_eq!(query(DVec3::new(f64::NAN, 0.0, 0.0), 1.0, 0.0, offer), None);
        assert_eq!(query(DVec3::new(0.0, f64::INFINITY, 0.0), 1.0, 0.0, offer), None);
        assert_eq!(query(DVec3::ZERO, -1.0, 0.0, offer), None);
        assert_eq!(query(DVec3::ZERO, f64::NAN, 0.0, offer), None);
        assert_eq!(query(DVec3::ZERO, 1.0, 0.0, offer).map(|n| n.prim), Some(0));
    }
}
