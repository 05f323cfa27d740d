//! The path tracer's wavefront (Laine, Karras & Aila 2013, "Megakernels Considered Harmful: Wavefront
//! Path Tracing on GPUs", here on a CPU thread): the paths of a batch of camera samples step together.
//! Each step shades every live path's hit with the one-path loop's own vertex ([`PathTracer::vertex`]),
//! which leaves its shadow rays here ([`Deferred`]); then the step's shadow rays go through the scene's
//! batched any-hit query and its bounce rays through the batched closest-hit query, whose BVH walks two
//! rays at once and so hides one ray's memory latency behind the other's.
//!
//! Invariants: every path draws the same numbers from its own stream, in the same order, and sums its
//! light in the same order as [`PathTracer::li_camera_hit`] (a vertex's shadow-ray light waits for the
//! step's any-hit batch, the course's roulette's weighing of the vertex's light with it, and both come
//! before the path's next vertex), so the radiance of every sample is the same, bit for bit, and so is
//! every image. Costs: per path in flight about 200 bytes of state, in buffers each thread keeps for its
//! next batch (growing them anew for every batch of 256 cost 1.5% of a Cornell box's instructions); per
//! step one any-hit and one closest-hit batch, and the state of each live path read and written once.

use super::light::Shadows;
use super::{PathState, PathTracer};
use crate::accel::Hit;
use crate::integrator::roulette;
use crate::integrator::split::Branches;
use crate::integrator::RayLog;
use crate::math::{Color, Ray};
use crate::renderer::Roulette;
use crate::sampler::SampleStream;
use crate::scene::SceneGeometry;
use std::cell::Cell;

/// One path in flight.
struct Path {
    /// The ray it traced last.
    ray: Ray,
    p: PathState,
    /// The light gathered so far.
    l: Color,
    branches: Branches,
}

/// What a step does with a path's light once its shadow rays are traced, in the order the one-path
/// loop does it.
enum Op {
    /// Light `c` of a vertex of `path`, which counts unless shadow ray `shadow` is blocked.
    Light { path: u32, shadow: u32, c: Color },
    /// The course's roulette's weighing of the light of a vertex of `path` ([`roulette::course_keep`]).
    Course { path: u32, q: f32, survives: bool },
}

/// A step's shadow rays and what waits on them.
struct Deferred<'w> {
    ops: &'w mut Vec<Op>,
    rays: &'w mut Vec<Ray>,
    t_max: &'w mut Vec<f32>,
    /// The path being shaded.
    path: u32,
}

impl Shadows for Deferred<'_> {
    #[inline(always)]
    fn cast(&mut self, _: &SceneGeometry, _: &mut RayLog, ray: &Ray, t_max: f32, c: Color, _: &mut Color) {
        self.ops.push(Op::Light { path: self.path, shadow: self.rays.len() as u32, c });
        self.rays.push(*ray);
        self.t_max.push(t_max);
    }

    #[inline(always)]
    fn course(&mut self, t: Color, _: &mut Color, _: &mut Color, sample: &mut SampleStream) -> Option<f32> {
        let (q, survives) = roulette::course_draw(t, sample);
        self.ops.push(Op::Course { path: self.path, q, survives });
        survives.then_some(q)
    }
}

/// A batch's buffers, kept by each thread between its batches.
#[derive(Default)]
struct Buffers {
    paths: Vec<Path>,
    /// The live paths, and the closest hits of their rays.
    live: Vec<u32>,
    hit: Vec<Option<Hit>>,
    /// The paths that go on after a step, and their next rays.
    next: Vec<u32>,
    next_rays: Vec<Ray>,
    ops: Vec<Op>,
    shadow_rays: Vec<Ray>,
    shadow_t_max: Vec<f32>,
    occluded: Vec<bool>,
}

thread_local! {
    /// Taken for a batch and put back after it (a nested call, which none makes, would find empty ones).
    static BUFFERS: Cell<Buffers> = Cell::default();
}

impl PathTracer<'_> {
    /// Radiance along each camera ray of a batch, `rays[i]` with closest hit `hits[i]` and random
    /// stream `streams[i]`, into `out[i]`: [`PathTracer::li_camera_hit`] of each, bit for bit, with the
    /// paths stepped together.
    ///
    /// # Panics
    /// When `rays`, `hits` and `streams` differ in length.
    pub fn li_camera_batch(
        &self,
        rays: &[Ray],
        hits: &[Option<Hit>],
        streams: &mut [SampleStream],
        log: &mut RayLog,
        out: &mut Vec<Color>,
    ) {
        assert!(rays.len() == hits.len() && rays.len() == streams.len(), "a batch's rays, hits and streams differ");
        let g = &self.scene.geometry;
        // Under the course's roulette a vertex's shadow-ray light is its own, which the roulette weighs.
        let course = self.options.roulette == Roulette::Course;
        log.rays += rays.len() as u64;
        let mut b = BUFFERS.take();
        let Buffers { paths, live, hit, next, next_rays, ops, shadow_rays, shadow_t_max, occluded } = &mut b;
        paths.clear();
        paths.extend(rays.iter().map(|&ray| Path {
            ray,
            p: PathState::camera(),
            l: Color::ZERO,
            branches: Branches::default(),
        }));
        live.clear();
        live.extend(0..rays.len() as u32);
        hit.clear();
        hit.extend_from_slice(hits);
        while !live.is_empty() {
            next.clear();
            next_rays.clear();
            ops.clear();
            shadow_rays.clear();
            shadow_t_max.clear();
            for (&i, &h) in live.iter().zip(hit.iter()) {
                let (path, sample) = (&mut paths[i as usize], &mut streams[i as usize]);
                let mut shadows = Deferred { ops, rays: shadow_rays, t_max: shadow_t_max, path: i };
                let step =
                    self.vertex(&path.ray, h, &mut path.p, &mut path.l, &mut path.branches, sample, log, &mut shadows);
                let ray = match step {
                    Some((origin, dir)) => Ray::new(origin, dir).with_time(path.ray.time),
                    None => match self.next_branch(&mut path.branches, sample) {
                        Some(b) => {
                            path.p = PathState::branch(&b, path.p.e);
                            b.ray
                        }
                        None => continue,
                    },
                };
                log.rays += 1;
                path.ray = ray;
                next.push(i);
                next_rays.push(ray);
            }
            occluded.resize(shadow_rays.len(), false);
            if !shadow_rays.is_empty() {
                log.occluded_many(g, shadow_rays, shadow_t_max, occluded);
            }
            for op in ops.iter() {
                match *op {
                    Op::Light { path, shadow, c } => {
                        if !occluded[shadow as usize] {
                            let path = &mut paths[path as usize];
                            *(if course { &mut path.p.e } else { &mut path.l }) += c;
                        }
                    }
                    Op::Course { path, q, survives } => {
                        let path = &mut paths[path as usize];
                        roulette::course_keep(path.p.e, q, survives, &mut path.l);
                        path.p.e = Color::ZERO;
                    }
                }
            }
            hit.resize(next_rays.len(), None);
            if !next_rays.is_empty() {
                log.intersect_scattered(g, next_rays, hit);
            }
            std::mem::swap(live, next);
        }
        out.clear();
        out.extend(paths.iter().map(|p| p.l));
        BUFFERS.set(b);
    }
}
