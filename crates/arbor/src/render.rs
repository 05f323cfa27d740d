//! Rendering one camera's image: 16x16 tiles traced in parallel over rayon. Each pixel sample draws from
//! its own random stream ([`crate::sampler`]), so the image does not depend on thread count or tile order.
//!
//! A debug view ([`RenderOptions::debug`]) either replaces the Whitted integrator by one ray through each
//! pixel centre ([`DebugIntegrator`]), or draws over the finished Whitted image (boxes).

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use rayon::prelude::*;

use crate::camera::Camera;
use crate::film::Film;
use crate::integrator::debug::{heatmap_finish, overlay_boxes, BOX_COLOR};
use crate::integrator::{DebugIntegrator, DebugView, Whitted};
use crate::math::Color;
use crate::sampler::{pixel_offset, Rng};
use crate::scene::Scene;

const TILE: u32 = 16;

/// Choices made for one render, on top of what the scene says.
#[derive(Debug, Clone, Default)]
pub struct RenderOptions {
    /// Samples per pixel, overriding the camera's `NumSamples`.
    pub spp: Option<u32>,
    /// Cull back faces for camera rays; `None` follows the scene (which defaults to no culling).
    pub cull_backfaces: Option<bool>,
    /// Render a debug view instead of (or over) the Whitted image.
    pub debug: Option<DebugView>,
}

/// What a render measured.
#[derive(Debug, Clone, Copy, Default)]
pub struct RenderStats {
    /// Rays traced: camera, shadow and secondary.
    pub rays: u64,
    /// Wall time.
    pub time: Duration,
    /// Samples per pixel used.
    pub spp: u32,
    /// The heatmap view's largest per-pixel cost (nodes visited plus primitives tested).
    pub heatmap_max: Option<u32>,
}

impl RenderStats {
    /// Millions of rays per second.
    pub fn mrays_per_s(&self) -> f64 {
        self.rays as f64 / self.time.as_secs_f64().max(1e-9) / 1e6
    }
}

/// Renders camera `camera` of `scene`. `progress(done, total)` is called (from worker threads) as pixels
/// complete.
pub fn render(
    scene: &Scene,
    camera: usize,
    opts: &RenderOptions,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> (Film, RenderStats) {
    let start = Instant::now();
    let desc = &scene.desc.cameras[camera];
    let cam = Camera::new(desc);
    let cull = opts.cull_backfaces.or(scene.desc.cull_backfaces).unwrap_or(false);
    let integrator = Whitted::new(scene, cull);
    // Views that do not shade trace the pixel centre once: their values do not average meaningfully.
    let debug = opts.debug.filter(|v| !v.shades()).map(|v| DebugIntegrator::new(scene, v, cull));
    let spp = if debug.is_some() { 1 } else { opts.spp.unwrap_or(desc.num_samples).max(1) };
    let (w, h) = (cam.width, cam.height);
    let tiles: Vec<(u32, u32)> =
        (0..h.div_ceil(TILE)).flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx * TILE, ty * TILE))).collect();
    let total = w as u64 * h as u64;
    let done = AtomicU64::new(0);
    let rays = AtomicU64::new(0);
    let scale = if debug.is_some() { 1.0 } else { scene.desc.radiance_scale };

    let rendered: Vec<((u32, u32), Vec<Color>)> = tiles
        .par_iter()
        .map(|&(x0, y0)| {
            let (x1, y1) = ((x0 + TILE).min(w), (y0 + TILE).min(h));
            let mut pixels = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
            let mut count = 0u64;
            for y in y0..y1 {
                for x in x0..x1 {
                    let mut sum = Color::ZERO;
                    for k in 0..spp {
                        let mut rng = Rng::for_sample(x, y, k);
                        let offset = pixel_offset(k, spp, &mut rng);
                        let ray = cam.ray(x, y, offset, rng.next_2d());
                        sum += match &debug {
                            Some(d) => {
                                count += 1;
                                d.li_camera(&ray)
                            }
                            None => integrator.li_camera(&ray, &mut rng, &mut count),
                        };
                    }
                    pixels.push(sum * (scale / spp as f32));
                }
            }
            rays.fetch_add(count, Ordering::Relaxed);
            let n = done.fetch_add(pixels.len() as u64, Ordering::Relaxed) + pixels.len() as u64;
            progress(n, total);
            ((x0, y0), pixels)
        })
        .collect();

    let mut film = Film::new(w, h);
    for ((x0, y0), pixels) in rendered {
        let tw = ((x0 + TILE).min(w) - x0) as usize;
        for (k, c) in pixels.into_iter().enumerate() {
            let (x, y) = (x0 as usize + k % tw, y0 as usize + k / tw);
            film.pixels[y * w as usize + x] = c;
        }
    }
    let heatmap_max = match opts.debug {
        Some(DebugView::Heatmap) => Some(heatmap_finish(&mut film)),
        Some(DebugView::Boxes { depth }) => {
            overlay_boxes(&mut film, desc, &scene.geometry.boxes_at_depth(depth), BOX_COLOR);
            None
        }
        _ => None,
    };
    let stats = RenderStats { rays: rays.into_inner(), time: start.elapsed(), spp, heatmap_max };
    (film, stats)
}
