//! Rendering one camera's image: 16x16 tiles traced in parallel over rayon. Each pixel sample draws from
//! its own random stream ([`crate::sampler`]), so the image does not depend on thread count or tile order.
//! A sample's random numbers are drawn in the course's order: the point in the pixel's stratum, the point
//! on the lens, the time in the shutter interval (only when something moves), then whatever shading
//! asks for.
//!
//! A crop ([`RenderOptions::crop`]) traces only the tiles of the full frame that overlap a window, with
//! the full frame's pixel coordinates and random streams, so its pixels are those of the full render.
//! A sample range ([`RenderOptions::samples`]) traces only samples `k0..k1` of the pixel's `spp`, each
//! with the stratum and random stream it has in the full render. Samples are summed exactly
//! ([`crate::accum`]), so sums of disjoint ranges add up to the full render's sum bit for bit;
//! [`render_sums`] returns those sums for a partial image ([`crate::farm`]).
//! A cancellation flag ([`RenderOptions::cancel`]) is checked before every tile: once set, the remaining
//! tiles are skipped and the result is marked [`RenderStats::cancelled`] (it must not be written).
//!
//! Within a tile the camera rays of a few pixels (up to 256 samples) are traced as one batch
//! ([`crate::scene::SceneGeometry::intersect_many`]: the BVH interleaves two rays), then shaded pixel by
//! pixel; secondary and shadow rays are traced one at a time. Batches give the same hits as single
//! queries, so the image does not depend on them either.
//!
//! A debug view ([`RenderOptions::debug`]) either replaces the Whitted integrator by one ray through each
//! pixel centre ([`DebugIntegrator`]), or draws over the finished Whitted image (boxes).

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use rayon::prelude::*;

mod probe;
use probe::camera_sample;
pub use probe::{back_face_share, inspect_sample, BACK_FACE_WARNING_SHARE};

use crate::accum::SampleSum;
use crate::camera::Camera;
use crate::error::Result;
use crate::film::{out_of_memory, Film};
use crate::integrator::debug::{heatmap_finish, overlay_boxes, BOX_COLOR};
use crate::integrator::{thread_time, DebugIntegrator, DebugView, Integrator, RayLog};
use crate::renderer::Renderer;
use crate::sampler::{SamplerKind, Strata};
use crate::scene::Scene;

const TILE: u32 = 16;
/// Camera rays traced as one batch (at least one pixel's samples): enough for the BVH's interleaved
/// traversal to stay busy, few enough that a tile's batch stays in cache.
const BATCH: usize = 256;

/// Choices made for one render, on top of what the scene says.
#[derive(Debug, Clone, Default)]
pub struct RenderOptions {
    /// Samples per pixel, overriding the camera's `NumSamples`.
    pub spp: Option<u32>,
    /// Cull back faces for camera rays; `None` follows the scene ([`Scene::cull_backfaces`]: its
    /// `BackfaceCulling`, else its form's default), and no culling when it makes no choice.
    pub cull_backfaces: Option<bool>,
    /// Render a debug view instead of (or over) the Whitted image.
    pub debug: Option<DebugView>,
    /// Render only the pixels `x0..x1` x `y0..y1` of the full frame (the film is the crop's size);
    /// clamped to the frame. Box overlays are drawn in full-frame coordinates; the heatmap is scaled by
    /// the crop's own maximum, and its legend shows where the crop covers the frame's bottom rows.
    pub crop: Option<(u32, u32, u32, u32)>,
    /// Trace only samples `k0..k1` of each pixel's `spp` (clamped to them); the film holds their mean.
    pub samples: Option<(u32, u32)>,
    /// Stop early when this becomes true (a signal handler sets it): no tile starts after that.
    pub cancel: Option<Arc<AtomicBool>>,
    /// The integrator, overriding the camera's `Renderer` (`--integrator`).
    pub renderer: Option<Renderer>,
    /// Picks every random choice of the render ([`crate::sampler::Rng::for_sample`]); renders with
    /// different seeds have independent noise.
    pub seed: u64,
    /// How the path tracer's random numbers are spread over a pixel's samples.
    pub sampler: SamplerKind,
    /// The heatmap view's colours run up to this cost instead of the image's own maximum (to show two
    /// structures' heatmaps on one scale).
    pub heatmap_scale: Option<u32>,
}

/// What a render measured.
#[derive(Debug, Clone, Copy, Default)]
pub struct RenderStats {
    /// Rays traced: camera, shadow and secondary.
    pub rays: u64,
    /// The time the structure's queries took, summed over threads (estimated from a sample of them,
    /// each tile's capped at its CPU time: [`RayLog`]).
    pub traversal: Duration,
    /// The CPU time the workers spent on tiles, summed over threads: not the time they waited for a
    /// core, nor for work.
    pub busy: Duration,
    /// Wall time.
    pub time: Duration,
    /// Samples per pixel of the full image (the stratification).
    pub spp: u32,
    /// The range of samples traced, `k0..k1` (all: `0..spp`).
    pub samples: (u32, u32),
    /// The heatmap view's largest per-pixel cost (nodes visited plus primitives tested).
    pub heatmap_max: Option<u32>,
    /// The render was cancelled before it finished: the film is incomplete.
    pub cancelled: bool,
    /// Camera samples whose Whitted ray tree reached its budget and dropped the rest
    /// ([`crate::integrator::TREE_BUDGET`]).
    pub capped_samples: u64,
}

impl RenderStats {
    /// Millions of rays per second.
    pub fn mrays_per_s(&self) -> f64 {
        self.rays as f64 / self.time.as_secs_f64().max(1e-9) / 1e6
    }

    /// The share of the workers' CPU time on tiles spent in the structure's queries (the rest is
    /// shading, sampling and the render loop), or `None` when nothing was traced. Other programs that
    /// take the cores change it little ([`RayLog`]: within a few points on a loaded 2-core machine).
    pub fn traversal_share(&self) -> Option<f64> {
        (self.busy > Duration::ZERO && self.traversal > Duration::ZERO)
            .then(|| (self.traversal.as_secs_f64() / self.busy.as_secs_f64()).min(1.0))
    }
}

/// Renders camera `camera` of `scene`. `progress(done, total)` is called (from worker threads) as pixels
/// complete. Fails only when the image's buffers cannot be allocated ([`crate::Error::OutOfMemory`]), before
/// any ray is traced for the film, or during tracing for the tiles' sums.
pub fn render(
    scene: &Scene,
    camera: usize,
    opts: &RenderOptions,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<(Film, RenderStats)> {
    render_camera(scene, &scene.cameras[camera], opts, progress)
}

/// [`render`] through any camera of the scene's, such as one a live view moved
/// ([`Camera::posed`]).
pub fn render_camera(
    scene: &Scene,
    cam: &Camera,
    opts: &RenderOptions,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<(Film, RenderStats)> {
    let (w, h) = (cam.width, cam.height);
    // Tiles land in a full-frame film (debug overlays are drawn in frame coordinates), cut at the end.
    let mut film = Film::try_new(w, h)?;
    let (traced, stats, scale) = trace(scene, cam, opts, progress)?;
    let count = stats.samples.1 - stats.samples.0;
    scatter(traced, (0, 0), w as usize, |i, s| film.pixels[i] = s.value(scale, count));
    let heatmap_max = match opts.debug {
        Some(DebugView::Heatmap) => Some(heatmap_finish(&mut film, opts.heatmap_scale)),
        Some(DebugView::Boxes { depth }) => {
            overlay_boxes(&mut film, cam, &scene.geometry.boxes_at_depth(depth), BOX_COLOR);
            None
        }
        _ => None,
    };
    let (cx0, cy0, cx1, cy1) = crop_window(opts.crop, w, h);
    if (cx0, cy0, cx1, cy1) != (0, 0, w, h) {
        film = cut(&film, cx0, cy0, cx1, cy1);
    }
    Ok((film, RenderStats { heatmap_max, ..stats }))
}

/// The exact sample sums of one render's window, for a partial image that `arbor merge` combines.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderSums {
    /// The full frame's width and height.
    pub frame: (u32, u32),
    /// The window rendered, `(x0, y0, x1, y1)` in frame pixels, end exclusive.
    pub window: (u32, u32, u32, u32),
    /// Samples per pixel of the full image.
    pub spp: u32,
    /// The samples summed, `k0..k1`.
    pub samples: (u32, u32),
    /// The scene's radiance scale, applied when the sums become pixels.
    pub scale: f32,
    /// Row-major sums of the window's pixels.
    pub sums: Vec<SampleSum>,
}

/// Like [`render`], but returns the exact per-pixel sums instead of a film. Debug views are not
/// supported (they are not sums of samples): `opts.debug` is ignored.
pub fn render_sums(
    scene: &Scene,
    camera: usize,
    opts: &RenderOptions,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<(RenderSums, RenderStats)> {
    let opts = RenderOptions { debug: None, ..opts.clone() };
    let cam = &scene.cameras[camera];
    let window = crop_window(opts.crop, cam.width, cam.height);
    let ww = (window.2 - window.0) as usize;
    let mut sums = sums_buffer(window)?;
    sums.resize(ww * (window.3 - window.1) as usize, SampleSum::default());
    let (traced, stats, scale) = trace(scene, cam, &opts, progress)?;
    scatter(traced, (window.0, window.1), ww, |i, s| sums[i] = s);
    let frame = (cam.width, cam.height);
    Ok((RenderSums { frame, window, spp: stats.spp, samples: stats.samples, scale, sums }, stats))
}

/// Hands each traced tile's sums to `put` with their row-major index in a buffer `width` pixels wide
/// whose first pixel is frame pixel `origin`.
fn scatter(traced: Traced, origin: (u32, u32), width: usize, mut put: impl FnMut(usize, SampleSum)) {
    for ((x0, y0, tw), tile, _, _) in traced {
        let (x0, y0, tw) = ((x0 - origin.0) as usize, (y0 - origin.1) as usize, tw as usize);
        for (k, s) in tile.into_iter().enumerate() {
            put((y0 + k / tw) * width + x0 + k % tw, s);
        }
    }
}

/// An empty buffer with room for the sums of `window`'s pixels, or [`crate::Error::OutOfMemory`].
fn sums_buffer(window: (u32, u32, u32, u32)) -> Result<Vec<SampleSum>> {
    let (w, h) = (window.2 - window.0, window.3 - window.1);
    let n = w as usize * h as usize;
    let mut sums = Vec::new();
    match sums.try_reserve_exact(n) {
        Ok(()) => Ok(sums),
        Err(_) => Err(out_of_memory(w, h, n as u64 * std::mem::size_of::<SampleSum>() as u64)),
    }
}

/// Bytes of one pixel's exact sample sums.
const SUM_BYTES: u64 = std::mem::size_of::<SampleSum>() as u64;

/// Per-tile sums over the crop window: `((x0, y0, tile width), sums, the tile's rays, its CPU time)`, the stats
/// and the radiance scale.
type Traced = Vec<((u32, u32, u32), Vec<SampleSum>, RayLog, Duration)>;

fn trace(
    scene: &Scene,
    cam: &Camera,
    opts: &RenderOptions,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<(Traced, RenderStats, f32)> {
    let start = Instant::now();
    let cull = opts.cull_backfaces.or(scene.cull_backfaces).unwrap_or(false);
    let integrator = Integrator::new(scene, cam, opts.renderer.unwrap_or(cam.renderer), cull);
    // Views that do not shade trace the pixel centre once: their values do not average meaningfully.
    let debug = opts.debug.filter(|v| !v.shades()).map(|v| DebugIntegrator::new(scene, v, cull));
    let spp = if debug.is_some() { 1 } else { opts.spp.unwrap_or(cam.num_samples).max(1) };
    let (k0, k1) = match opts.samples {
        Some((k0, k1)) if debug.is_none() => (k0.min(spp - 1), k1.clamp(k0.min(spp - 1) + 1, spp)),
        _ => (0, spp),
    };
    let (w, h) = (cam.width, cam.height);
    let (cx0, cy0, cx1, cy1) = crop_window(opts.crop, w, h);
    // The full frame's tile grid, cut to the window: pixel values do not depend on it, only on (x, y, k).
    let tiles: Vec<(u32, u32, u32, u32)> = (cy0 / TILE..cy1.div_ceil(TILE))
        .flat_map(|ty| (cx0 / TILE..cx1.div_ceil(TILE)).map(move |tx| (tx * TILE, ty * TILE)))
        .map(|(x, y)| (x.max(cx0), y.max(cy0), (x + TILE).min(cx1), (y + TILE).min(cy1)))
        .collect();
    let total = (cx1 - cx0) as u64 * (cy1 - cy0) as u64;
    let is_cancelled = || opts.cancel.as_ref().is_some_and(|c| c.load(Ordering::Relaxed));
    let done = AtomicU64::new(0);
    let scale = if debug.is_some() { 1.0 } else { scene.radiance_scale };
    let moving = scene.geometry.has_motion();
    let strata = Strata::new(spp);

    let traced: Result<Traced> = tiles
        .par_iter()
        .filter(|_| !is_cancelled())
        .map(|&(x0, y0, x1, y1)| {
            // Every tile's sums are kept until the image is assembled: together, one per pixel.
            let mut pixels =
                sums_buffer((x0, y0, x1, y1)).map_err(|_| out_of_memory(cx1 - cx0, cy1 - cy0, total * SUM_BYTES))?;
            let tile_start = thread_time();
            // A phase per tile (a hash of its place), so that small tiles' queries get timed too.
            let mut log =
                RayLog::with_phase((x0 / TILE).wrapping_mul(0x9E37_79B1) ^ (y0 / TILE).wrapping_mul(0x85EB_CA6B));
            let tile: Vec<(u32, u32)> = (y0..y1).flat_map(|y| (x0..x1).map(move |x| (x, y))).collect();
            // The camera rays of a few pixels are traced as one batch, then shaded pixel by pixel.
            let samples = (k1 - k0) as usize;
            let per_batch = (BATCH / samples).max(1);
            let (mut batch, mut streams, mut hits, mut radiance) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
            for group in tile.chunks(per_batch) {
                batch.clear();
                streams.clear();
                for &(x, y) in group {
                    for k in k0..k1 {
                        let (ray, sample) = camera_sample(cam, opts, strata, moving, (x, y, k));
                        batch.push(match &debug {
                            Some(_) => ray,
                            None => integrator.camera_ray(&ray),
                        });
                        streams.push(sample);
                    }
                }
                radiance.clear();
                match &debug {
                    Some(d) => radiance.extend(batch.iter().map(|r| {
                        log.rays += 1;
                        d.li_camera(r)
                    })),
                    None => {
                        hits.resize(batch.len(), None);
                        log.intersect_many(&scene.geometry, &batch, f32::INFINITY, &mut hits);
                        integrator.li_camera_batch(&batch, &hits, &mut streams, &mut log, &mut radiance);
                    }
                }
                for pixel in radiance.chunks(samples) {
                    let mut sum = SampleSum::default();
                    for &c in pixel {
                        sum.add_sample(c);
                    }
                    pixels.push(sum);
                }
            }
            let n = done.fetch_add(pixels.len() as u64, Ordering::Relaxed) + pixels.len() as u64;
            progress(n, total);
            Ok(((x0, y0, x1 - x0), pixels, log, thread_time().saturating_sub(tile_start)))
        })
        .collect();
    let traced = traced?;
    let cancelled = is_cancelled();
    let (mut rays, mut traversal, mut busy, mut capped_samples) = (0, Duration::ZERO, Duration::ZERO, 0);
    for (_, _, log, cpu) in &traced {
        rays += log.rays;
        capped_samples += log.capped_samples;
        traversal += log.traversal_within(*cpu);
        busy += *cpu;
    }
    let stats = RenderStats {
        rays,
        traversal,
        busy,
        time: start.elapsed(),
        spp,
        samples: (k0, k1),
        heatmap_max: None,
        cancelled,
        capped_samples,
    };
    Ok((traced, stats, scale))
}

/// The crop window clamped to a `w` x `h` frame, as `(x0, y0, x1, y1)` with `x0 < x1`, `y0 < y1` unless the
/// frame is empty; no crop is the whole frame.
pub fn crop_window(crop: Option<(u32, u32, u32, u32)>, w: u32, h: u32) -> (u32, u32, u32, u32) {
    match crop {
        None => (0, 0, w, h),
        Some((x0, y0, x1, y1)) => {
            let (x1, y1) = (x1.min(w), y1.min(h));
            (x0.min(x1.saturating_sub(1)), y0.min(y1.saturating_sub(1)), x1, y1)
        }
    }
}

/// The pixels `x0..x1` x `y0..y1` of `film`.
fn cut(film: &Film, x0: u32, y0: u32, x1: u32, y1: u32) -> Film {
    let mut out = Film::new(x1 - x0, y1 - y0);
    for y in y0..y1 {
        let row = (y * film.width) as usize;
        let dst = ((y - y0) * out.width) as usize;
        out.pixels[dst..dst + out.width as usize].copy_from_slice(&film.pixels[row + x0 as usize..row + x1 as usize]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::AccelConfig;
    use crate::scene::parse_desc;

    /// A 24x16 view of two walls meeting at x = 0, the left one wound `left`, the right one `right`
    /// (`1 2 3 1 3 4`: facing the camera; `1 3 2 1 4 3`: its back to it).
    fn walls(left: &str, right: &str) -> Scene {
        let text = format!(
            r#"<Scene>
                <Cameras><Camera id="1">
                    <Position>0 0 5</Position><Gaze>0 0 -1</Gaze><Up>0 1 0</Up><NearPlane>-1 1 -1 1</NearPlane>
                    <NearDistance>2</NearDistance><ImageResolution>24 16</ImageResolution><ImageName>w.png</ImageName>
                </Camera></Cameras>
                <Materials><Material id="1">
                    <AmbientReflectance>1 1 1</AmbientReflectance><DiffuseReflectance>1 1 1</DiffuseReflectance>
                </Material></Materials>
                <VertexData>-10 -10 0  0 -10 0  0 10 0  -10 10 0  10 -10 0  10 10 0</VertexData>
                <Objects>
                    <Mesh id="1"><Material>1</Material><Faces>{left}</Faces></Mesh>
                    <Mesh id="2"><Material>1</Material><Faces>{right}</Faces></Mesh>
                </Objects>
            </Scene>"#
        );
        let desc = parse_desc(&text, std::path::Path::new("walls.xml")).unwrap();
        Scene::build(desc, &AccelConfig::default(), None).unwrap()
    }

    #[test]
    fn back_face_share_counts_the_camera_rays_whose_first_hit_culling_would_skip() {
        let (front, back) = ("1 2 3 1 3 4", "1 3 2 1 4 3");
        // The right wall is the left one moved by 10 in x (vertices 2 5 6 3 for 1 2 3 4).
        let (right_front, right_back) = ("2 5 6 2 6 3", "2 6 5 2 3 6");
        assert_eq!(back_face_share(&walls(front, right_front), 0), 0.0);
        assert_eq!(back_face_share(&walls(back, right_back), 0), 1.0);
        // Half the image: not "most" of it.
        let half = back_face_share(&walls(back, right_front), 0);
        assert_eq!(half, 0.5);
        assert!(half <= BACK_FACE_WARNING_SHARE);
    }

    #[test]
    fn render_stats_traversal_is_within_the_tiles_cpu_time() {
        let scene = walls("1 2 3 1 3 4", "2 5 6 2 6 3");
        let (_, stats) = render(&scene, 0, &RenderOptions { spp: Some(16), ..Default::default() }, &|_, _| {}).unwrap();
        assert!(stats.traversal > Duration::ZERO && stats.traversal <= stats.busy, "{stats:?}");
        assert!(stats.traversal_share().is_some_and(|s| s > 0.0 && s <= 1.0));
    }
}
