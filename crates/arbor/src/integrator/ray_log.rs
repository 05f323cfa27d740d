//! What one render worker's rays cost: how many were traced, and how long the structure's queries took,
//! measured on a sample of them. Reading the clock around every query would cost a fifth of a small
//! scene's render (a clock read is tens of nanoseconds, a query a few hundred); one single query in
//! [`TIMED_EVERY`] is timed instead and scaled up, which leaves the sampling noise of a few thousand
//! timed queries (well under 1%) on any render long enough to read the figure from. The clock's own
//! cost, measured once, is taken off each timed query. Each tile's log starts at its own phase
//! ([`RayLog::with_phase`]), so that every query has the same chance of being timed in a tile of any
//! size. Batches of camera rays, which are few and long, are all timed.
//!
//! The wall clock times single queries. A timed query during which the thread waited for a core counts
//! that wait as query time, 64 times over: on a 2-core machine shared with other programs, the
//! traversal share of one scene moved from 32% to 71% to 38% between runs (and to 100%). The thread's
//! CPU clock ([`thread_time`]) stands still while the thread waits, but it is a system call (about
//! 0.3-0.5 µs here, ten times the wall clock): timing single queries on it cost 6% of the Cornell box's
//! render and read `ton_Roosendaal_smooth` at 80% where timing every query on the wall clock reads 58%.
//! So the CPU clock times only what is long: batches, and each tile (four reads per tile of 256 pixels
//! at one sample: about 2% of the Cornell box's render, nothing measurable on meshes); and a tile's
//! query time is capped at the tile's CPU time ([`RayLog::traversal_within`]), which no true estimate
//! exceeds. A wait caught by a timed query then costs at most its tile's share of the render rather
//! than 64 times the wait: five runs under a load of 12 on 2 cores read 63% five times on
//! `ton_Roosendaal_smooth`, 57-58% on `two_berserkers`, 47-48% on `cornellbox_recursive`.
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
    /// Queries since the log began, plus its phase.
    queries: u64,
    timed_queries: u64,
    timed: Duration,
    batches: Duration,
}

impl RayLog {
    /// An empty log whose first timed query is its `TIMED_EVERY - phase % TIMED_EVERY`-th: logs with
    /// phases spread over `0..TIMED_EVERY` time each query with the same chance, `1 / TIMED_EVERY`.
    pub fn with_phase(phase: u32) -> RayLog {
        RayLog { queries: u64::from(phase % TIMED_EVERY), ..RayLog::default() }
    }

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

    /// [`SceneGeometry::intersect_many`], always timed on the thread's CPU clock (a batch is worth
    /// many clock reads); not counted.
    pub fn intersect_many(&mut self, g: &SceneGeometry, rays: &[Ray], t_max: f32, out: &mut [Option<Hit>]) {
        self.batch(|| g.intersect_many(rays, t_max, out));
    }

    /// [`SceneGeometry::intersect_scattered`] for a batch of secondary rays, timed as
    /// [`RayLog::intersect_many`]; not counted.
    pub fn intersect_scattered(&mut self, g: &SceneGeometry, rays: &[Ray], out: &mut [Option<Hit>]) {
        self.batch(|| g.intersect_scattered(rays, out));
    }

    /// [`SceneGeometry::occluded_many`], timed as [`RayLog::intersect_many`]; not counted.
    pub fn occluded_many(&mut self, g: &SceneGeometry, rays: &[Ray], t_max: &[f32], out: &mut [bool]) {
        self.batch(|| g.occluded_many(rays, t_max, out));
    }

    /// Runs the batch query `f`, timed on the thread's CPU clock into the batches' time.
    fn batch(&mut self, f: impl FnOnce()) {
        let start = thread_time();
        f();
        self.batches += thread_time().saturating_sub(start);
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

    /// The time all queries took: the timed ones' time, less the clock's own cost in each, times
    /// [`TIMED_EVERY`] (each query was timed with chance `1 / TIMED_EVERY`), plus the batches'.
    pub fn traversal(&self) -> Duration {
        let clock = clock_cost().saturating_mul(self.timed_queries.min(u32::MAX as u64) as u32);
        self.batches + self.timed.saturating_sub(clock) * TIMED_EVERY
    }

    /// [`RayLog::traversal`] of a tile that took `cpu` of its thread's CPU time, capped at it: above it
    /// the estimate holds a wait for a core that a timed query caught, scaled up.
    pub fn traversal_within(&self, cpu: Duration) -> Duration {
        self.traversal().min(cpu)
    }
}

/// What reading the clock twice costs, the least of a few tries (measured once).
fn clock_cost() -> Duration {
    static COST: std::sync::OnceLock<Duration> = std::sync::OnceLock::new();
    *COST.get_or_init(|| (0..64).map(|_| Instant::now().elapsed()).min().unwrap_or_default())
}

/// The CPU time the calling thread has used: it does not advance while the thread waits to run.
#[cfg(target_os = "linux")]
pub fn thread_time() -> Duration {
    let mut t = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `t` is a valid timespec for the call to fill.
    if unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut t) } != 0 {
        return Duration::ZERO;
    }
    Duration::new(t.tv_sec.max(0) as u64, t.tv_nsec.clamp(0, 999_999_999) as u32)
}

/// Elsewhere, the wall time since the first call (a thread's waits then count).
#[cfg(not(target_os = "linux"))]
pub fn thread_time() -> Duration {
    static START: std::sync::OnceLock<Instant> = std::sync::OnceLock::new();
    START.get_or_init(Instant::now).elapsed()
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
        assert_eq!(RayLog::default().traversal(), Duration::ZERO);
    }

    #[test]
    fn ray_log_phases_time_every_query_with_the_same_chance() {
        // A tile of 10 queries: over the 64 phases, each query is timed in exactly one.
        let mut timed = vec![0u32; 10];
        for phase in 0..TIMED_EVERY {
            let mut log = RayLog::with_phase(phase);
            for (k, t) in timed.iter_mut().enumerate() {
                let before = log.timed_queries;
                assert_eq!(log.query(|| k), k);
                *t += (log.timed_queries - before) as u32;
            }
        }
        assert_eq!(timed, vec![1; 10]);
    }

    #[test]
    fn ray_log_caps_a_tiles_query_time_at_the_tiles_cpu_time() {
        // One timed query that caught a 2 ms wait for a core: 128 ms once scaled, in a 5 ms tile.
        let log = RayLog { queries: 64, timed_queries: 1, timed: Duration::from_millis(2), ..RayLog::default() };
        assert!(log.traversal() > Duration::from_millis(100));
        assert_eq!(log.traversal_within(Duration::from_millis(5)), Duration::from_millis(5));
        let quiet = RayLog { batches: Duration::from_millis(1), ..RayLog::default() };
        assert_eq!(quiet.traversal_within(Duration::from_millis(5)), Duration::from_millis(1));
    }

    #[test]
    #[cfg(target_os = "linux")]
    fn thread_time_stands_still_while_the_thread_sleeps() {
        // Not a speed check: a sleeping thread uses next to no CPU time, whatever the machine's load.
        let start = thread_time();
        std::thread::sleep(Duration::from_millis(200));
        let used = thread_time() - start;
        assert!(used < Duration::from_millis(100), "{used:?}");
    }
}
