//! Integrators: what colour a camera ray brings back. [`Integrator`] is the one a camera's image uses.

pub mod debug;
mod hemisphere;
pub mod offset;
mod path;
mod prune;
mod ray_log;
mod roulette;
mod split;
mod whitted;

pub use debug::{DebugIntegrator, DebugView};
pub use hemisphere::{cosine_hemisphere, uniform_hemisphere};
pub use path::PathTracer;
pub use prune::{Pruning, TreePlan, PRUNED_LEVELS, TREE_BUDGET};
pub use ray_log::{thread_time, RayEvent, RayLog, TIMED_EVERY};
pub use roulette::MAX_BOUNCES;
pub use whitted::Whitted;

use crate::accel::Hit;
use crate::camera::Camera;
use crate::math::{Color, Ray};
use crate::renderer::Renderer;
use crate::sampler::SampleStream;
use crate::scene::Scene;

/// The integrator of one camera's image.
pub enum Integrator<'a> {
    /// Whitted-style ray tracing.
    Whitted(Whitted<'a>),
    /// Path tracing.
    Path(PathTracer<'a>),
}

impl<'a> Integrator<'a> {
    /// The integrator `renderer` names, for `camera`'s rays over `scene`; `cull_backfaces` applies to
    /// camera rays only.
    pub fn new(scene: &'a Scene, camera: &'a Camera, renderer: Renderer, cull_backfaces: bool) -> Self {
        match renderer {
            Renderer::Whitted => Integrator::Whitted(Whitted::new(scene, cull_backfaces).with_camera(camera)),
            Renderer::PathTracing(o) => Integrator::Path(PathTracer::new(scene, o, cull_backfaces).with_camera(camera)),
        }
    }

    /// The camera ray as it is traced (culled or not).
    pub fn camera_ray(&self, ray: &Ray) -> Ray {
        match self {
            Integrator::Whitted(w) => w.camera_ray(ray),
            Integrator::Path(p) => p.camera_ray(ray),
        }
    }

    /// Radiance along the camera ray `ray` (from [`Integrator::camera_ray`]) whose closest hit is `hit`.
    pub fn li_camera_hit(&self, ray: &Ray, hit: Option<Hit>, sample: &mut SampleStream, log: &mut RayLog) -> Color {
        match self {
            Integrator::Whitted(w) => w.li_camera_hit(ray, hit, &mut sample.rng, log),
            Integrator::Path(p) => p.li_camera_hit(ray, hit, sample, log),
        }
    }

    /// [`Integrator::li_camera_hit`] of each camera ray of a batch (`rays[i]`, `hits[i]`,
    /// `streams[i]`) into `out[i]`: the same values; the path tracer steps the batch's paths together
    /// (its wavefront), Whitted's integrator takes them one by one.
    pub fn li_camera_batch(
        &self,
        rays: &[Ray],
        hits: &[Option<Hit>],
        streams: &mut [SampleStream],
        log: &mut RayLog,
        out: &mut Vec<Color>,
    ) {
        match self {
            Integrator::Path(p) => p.li_camera_batch(rays, hits, streams, log, out),
            Integrator::Whitted(_) => {
                out.clear();
                for ((r, h), s) in rays.iter().zip(hits).zip(streams) {
                    out.push(self.li_camera_hit(r, *h, s, log));
                }
            }
        }
    }
}
