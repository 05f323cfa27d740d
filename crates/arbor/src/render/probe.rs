//! Single rays of a render, apart from the render: the camera sample every pixel starts from
//! ([`camera_sample`], which the render loop uses too, so the two never drift apart), one sample traced
//! with every query recorded ([`inspect_sample`], for a live view's ray inspector), and the share of a
//! camera's rays that meet back faces ([`back_face_share`], for the culling warning).

use super::RenderOptions;
use crate::camera::Camera;
use crate::integrator::{Integrator, RayEvent, RayLog};
use crate::math::{Color, Ray};
use crate::sampler::{SampleStream, Strata};
use crate::scene::Scene;

/// Sample `k` of pixel `(x, y)`: its camera ray (before culling) and the random stream its shading
/// continues.
pub(super) fn camera_sample(
    cam: &Camera,
    opts: &RenderOptions,
    strata: Strata,
    moving: bool,
    (x, y, k): (u32, u32, u32),
) -> (Ray, SampleStream) {
    let mut sample = SampleStream::new(opts.sampler, x, y, k, opts.seed, strata);
    let offset = sample.pixel_offset(strata, k);
    let ray = cam.ray(x, y, offset, sample.rng.next_2d());
    // A time is drawn only when something moves, so still scenes keep their streams.
    let ray = if moving { ray.with_time(sample.rng.next_f32()) } else { ray };
    (ray, sample)
}

/// What sample `k` of pixel `(x, y)` of `cam` traces, as [`super::render`] traces it (its integrator, random
/// numbers and culling from `opts`): the radiance it brings back, in the scene's units, and every
/// query in order, the camera ray's first ([`RayLog::recording`]).
pub fn inspect_sample(
    scene: &Scene,
    cam: &Camera,
    opts: &RenderOptions,
    (x, y, k): (u32, u32, u32),
) -> (Color, Vec<RayEvent>) {
    let cull = opts.cull_backfaces.or(scene.cull_backfaces).unwrap_or(false);
    let integrator = Integrator::new(scene, cam, opts.renderer.unwrap_or(cam.renderer), cull);
    let spp = opts.spp.unwrap_or(cam.num_samples).max(1);
    let (ray, mut sample) =
        camera_sample(cam, opts, Strata::new(spp), scene.geometry.has_motion(), (x, y, k.min(spp - 1)));
    let mut log = RayLog::recording();
    let ray = integrator.camera_ray(&ray);
    let hit = log.intersect(&scene.geometry, &ray, f32::INFINITY);
    let color = integrator.li_camera_hit(&ray, hit, &mut sample, &mut log);
    (color, log.record.unwrap_or_default())
}

/// The side of the grid of pixels whose camera rays [`back_face_share`] traces (at most 64 x 64).
const FACING_GRID: u32 = 64;

/// Above this share of camera rays meeting back faces, an unculled render is probably not what the
/// scene meant ("most" of them: more than half).
pub const BACK_FACE_WARNING_SHARE: f64 = 0.5;

/// The share of camera `camera`'s rays whose first hit is a back face: a hit that back-face culling
/// would skip (a triangle or plane met from behind). Estimated apart from any render, from the rays
/// through the centres of at most 64² (`FACING_GRID`) pixels spread evenly over the image (mid-shutter,
/// through the lens centre), each traced with and without culling: 8,192 queries at most, 1 to 6 ms on
/// the shared scenes, plenty to tell "most" from "some". The image itself is not touched.
pub fn back_face_share(scene: &Scene, camera: usize) -> f64 {
    let cam = &scene.cameras[camera];
    let (nx, ny) = (cam.width.min(FACING_GRID), cam.height.min(FACING_GRID));
    let centre = crate::math::Vec2::splat(0.5);
    let moving = scene.geometry.has_motion();
    // The middle pixel of the k-th of n equal strips of `side` pixels.
    let middle = |k: u32, n: u32, side: u32| ((2 * k as u64 + 1) * side as u64 / (2 * n as u64)) as u32;
    let mut back = 0u32;
    for j in 0..ny {
        for i in 0..nx {
            let (x, y) = (middle(i, nx, cam.width), middle(j, ny, cam.height));
            let mut ray = cam.ray(x, y, centre, centre);
            if moving {
                ray = ray.with_time(0.5);
            }
            let open = scene.geometry.intersect(&ray.with_culling(false), f32::INFINITY);
            let culled = scene.geometry.intersect(&ray.with_culling(true), f32::INFINITY);
            // A front face at the same distance (coincident faces) is what culling shows there too.
            back += u32::from(open.is_some_and(|o| culled.is_none_or(|c| c.t > o.t)));
        }
    }
    f64::from(back) / (f64::from(nx) * f64::from(ny)).max(1.0)
}
