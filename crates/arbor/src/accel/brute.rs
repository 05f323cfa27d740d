//! Brute force: every ray tests every primitive. The reference every other structure is checked against,
//! and the baseline of `arbor bench`'s speedups.

use std::time::Instant;

use super::{Accel, AccelStats, Hit, Primitives};
use crate::math::{Aabb, Ray};

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
        let mut best: Option<Hit> = None;
        let mut t_best = t_max;
        for i in 0..self.len {
            // `<=` keeps candidates at the current best t, so that ties resolve to the lowest index
            // whatever the order; ascending order makes the first one found win.
            if let Some(h) = prims.intersect(i, ray, t_best.next_up_or_inf()) {
                let hit = Hit::new(i as u32, h);
                if hit.t <= t_best && hit.beats(&best) {
                    t_best = hit.t;
                    best = Some(hit);
                }
            }
        }
        best
    }

    fn occluded(&self, prims: &P, ray: &Ray, t_max: f32) -> bool {
        (0..self.len).any(|i| prims.intersect(i, ray, t_max).is_some())
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

/// `next_up` for positive floats, stable in Rust 1.86; spelled out for older toolchains.
trait NextUp {
    fn next_up_or_inf(self) -> Self;
}

impl NextUp for f32 {
    #[inline]
    fn next_up_or_inf(self) -> f32 {
        if self.is_infinite() || self.is_nan() {
            self
        } else if self == 0.0 {
            f32::from_bits(1)
        } else if self > 0.0 {
            f32::from_bits(self.to_bits() + 1)
        } else {
            f32::from_bits(self.to_bits() - 1)
        }
    }
}
