//! What one render worker's rays cost: how many were traced, and how long the structure's queries took,
//! measured on a sample of them. Reading the clock around every query would cost a fifth of a small
//! scene's render (a clock read is tens of nanoseconds, a query a few hundred); one single query in
//! [`TIMED_EVERY`] is timed instead and the total scaled up (batches, which are few and long, are all
//! timed, so the sample never lines up with them), which leaves the sampling noise of a few
//! thousand timed queries (well under 1%) on any render long enough to read the figure from. The clock's
//! own cost, measured once, is taken off each timed query.
//!
//! A log can also keep every query it answers ([`RayLog::recording`]): the rays of one pixel's sample,
//! in the order the integrator traced them, for a live view's ray inspector.

use std::time::{Duration, Instant};

use crate::accel::Hit;
use crate::math::Ray;
use crate::scene::SceneGeometry;

/// One query in this many is timed.
pub const TIMED_EVERY: u32 = 64;

/// One query a recording log answered.
#[derive(Debug, Clone, Copy)]
pub struct RayEvent {
    /// The ray.
    pub ray: Ray,
    /// The far end of the query's interval.
    pub t_max: f32,
    /// A closest-hit query's hit; `None` for a miss and for an any-hit query.
    pub hit: Option<Hit>,
    /// `Some(occluded)` for an any-hit (shadow) query.
    pub occluded: Option<bool>,
}

/// Rays traced by one worker and the sampled time of their queries.
#[derive(Debug, Clone, Default)]
pub struct RayLog {
    /// Rays traced: camera, shadow and secondary.
    pub rays: u64,
    /// Rays of the current camera sample's Whitted tree (camera and secondary, not shadow rays).
    pub tree: u32,
    /// Whether the current sample's tree reached its budget and dropped branches.
    pub capped: bool,
    /// Camera samples whose trees reached their budget.
    pub capped_samples: u64,
    /// Every query answered, when recording ([`RayLog::recording`]).
    pub record: Option<Vec<RayEvent>>,
    queries: u64,
    timed_queries: u64,
    timed: Duration,
    batches: Duration,
}

impl RayLog {
    /// The closest hit of `ray` in `(0, t_max)` ([`SceneGeometry::intersect`]); not counted as a ray
    /// (the integrators count their rays where they decide to trace them).
    #[inline]
    pub fn intersect(&mut self, g: &SceneGeometry, ray: &Ray, t_max: f32) -> Option<Hit> {
        let hit = self.query(|| g.intersect(ray, t_max));
        if let Some(r) = &mut self.record {
            r.push(RayEvent { ray: *ray, t_max, hit, occluded: None });
        }
        hit
    }

    /// Whether anything lies on `ray` in `(0, t_max)` ([`SceneGeometry::occluded`]); not counted.
    #[inline]
    pub fn occluded(&mut self, g: &SceneGeometry, ray: &Ray, t_max: f32) -> bool {
        let occluded = self.query(|| g.occluded(ray, t_max));
        if let Some(r) = &mut self.record {
            r.push(RayEvent { ray: *ray, t_max, hit: None, occluded: Some(occluded) });
        }
        occluded
    }

    /// A log that keeps every query it answers, in [`RayLog::record`].
    pub fn recording() -> RayLog {
        RayLog { record: Some(Vec::new()), ..RayLog::default() }
    }

    /// [`SceneGeometry::intersect_many`], always timed (a batch is worth many clock reads); not counted.
    pub fn intersect_many(&mut self, g: &SceneGeometry, rays: &[Ray], t_max: f32, out: &mut [Option<Hit>]) {
        let start = Instant::now();
        g.intersect_many(rays, t_max, out);
        self.batches += start.elapsed();
    }

    #[inline(always)]
    fn query<T>(&mut self, f: impl FnOnce() -> T) -> T {
        self.queries += 1;
        if !self.queries.is_multiple_of(TIMED_EVERY as u64) {
            return f();
        }
        let start = Instant::now();
        let out = f();
        self.timed += start.elapsed();
        self.timed_queries += 1;
        out
    }

    /// The time all queries took, estimated from the timed ones, less the clock's own cost in each.
    pub fn traversal(&self) -> Duration {
        if self.timed_queries == 0 {
            return self.batches;
        }
        let clock = clock_cost().saturating_mul(self.timed_queries.min(u32::MAX as u64) as u32);
        self.batches + self.timed.saturating_sub(clock).mul_f64(self.queries as f64 / self.timed_queries as f64)
    }

    /// Adds `other`'s rays and times to these.
    pub fn merge(&mut self, other: &RayLog) {
        self.rays += other.rays;
        self.capped_samples += other.capped_samples;
        self.queries += other.queries;
        self.timed_queries += other.timed_queries;
        self.timed += other.timed;
        self.batches += other.batches;
    }
}

/// What reading the clock twice costs, the least of a few tries (measured once).
fn clock_cost() -> Duration {
    static COST: std::sync::OnceLock<Duration> = std::sync::OnceLock::new();
    *COST.get_or_init(|| (0..64).map(|_| Instant::now().elapsed()).min().unwrap_or_default())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ray_log_times_one_query_in_sixty_four_and_scales_it_up() {
        let mut log = RayLog::default();
        let answers: Vec<u32> = (0..256).map(|i| log.query(|| i)).collect();
        assert_eq!(answers, (0..256).collect::<Vec<_>>(), "every query's answer comes back");
        assert_eq!((log.queries, log.timed_queries), (256, 4));
        // Four timed queries stand for 256: their time, less the clock's, is scaled by 64.
        log.timed = Duration::from_micros(10);
        assert_eq!(log.traversal(), (Duration::from_micros(10) - clock_cost() * 4) * 64);
        let mut sum = RayLog { rays: 3, ..RayLog::default() };
        sum.merge(&log);
        assert_eq!((sum.rays, sum.queries, sum.timed_queries, sum.timed), (3, 256, 4, log.timed));
        assert_eq!(RayLog::default().traversal(), Duration::ZERO);
    }
}
