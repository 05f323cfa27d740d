//! Brute force: every ray tests every primitive, and every closest-point query weighs every primitive.
//! The reference every other structure is checked against, and the baseline of `arbor bench`'s speedups.

use std::time::Instant;

use super::closest::ClosestHit;
use super::nearest;
use super::{Accel, AccelStats, Hit, Nearest, Primitives, TraversalCounts};
use crate::math::{Aabb, DVec3, Ray};

/// No structure at all; only the bounds are kept.
#[derive(Debug, Clone)]
pub struct BruteForce {
    bounds: Aabb,
    len: usize,
    stats: AccelStats,
}

impl BruteForce {
    /// "Builds" over `prims`: computes the bounds.
    pub fn build<P: Primitives + ?Sized>(prims: &P) -> Self {
        let start = Instant::now();
        let bounds = (0..prims.len()).fold(Aabb::EMPTY, |b, i| b.union(prims.bounds(i)));
        let len = prims.len();
        let stats = AccelStats {
            kind: "brute",
            primitives: len,
            nodes: 1,
            leaves: 1,
            max_depth: 0,
            mean_depth: 0.0,
            refs_per_prim: 1.0,
            mean_leaf_prims: len as f64,
            sah_cost: len as f64,
            bytes: std::mem::size_of::<Self>(),
            build_time: start.elapsed(),
        };
        BruteForce { bounds, len, stats }
    }
}

impl<P: Primitives + ?Sized> Accel<P> for BruteForce {
    fn bounds(&self) -> Aabb {
        self.bounds
    }

    fn intersect(&self, prims: &P, ray: &Ray, t_max: f32) -> Option<Hit> {
        let mut best = ClosestHit::new(t_max);
        for i in 0..self.len {
            if let Some(h) = prims.intersect(i, ray, best.t_query()) {
                best.offer(Hit::new(i as u32, h));
            }
        }
        best.hit()
    }

    fn intersect_counted(&self, prims: &P, ray: &Ray, t_max: f32, counts: &mut TraversalCounts) -> Option<Hit> {
        counts.nodes += 1;
        let mut best = ClosestHit::new(t_max);
        for i in 0..self.len {
            if let Some(h) = prims.intersect_counted(i, ray, best.t_query(), counts) {
                best.offer(Hit::new(i as u32, h));
            }
        }
        best.hit()
    }

    fn closest_point(&self, prims: &P, p: DVec3, max_dist2: f64) -> Option<Nearest> {
        nearest::query(p, max_dist2, 0.0, |best| {
            for i in 0..self.len {
                best.offer(i as u32, prims.closest_point(i, p));
            }
        })
    }

    fn boxes_at_depth(&self, _: &P, depth: usize) -> Vec<Aabb> {
        if depth == 0 && !self.bounds.is_empty() {
            vec![self.bounds]
        } else {
            Vec::new()
        }
    }

    fn occluded(&self, prims: &P, ray: &Ray, t_max: f32) -> bool {
        (0..self.len).any(|i| prims.occludes(i, ray, t_max))
    }

    fn stats(&self) -> AccelStats {
        self.stats.clone()
    }

    fn validate(&self, prims: &P) -> Result<(), String> {
        if self.len != prims.len() {
            return Err(format!("built over {} primitives, queried with {}", self.len, prims.len()));
        }
        Ok(())
    }
}
