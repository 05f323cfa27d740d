//! The progressive render of the current view, on a thread of its own.
//!
//! A view ([`ViewRequest`]) is a camera of the scene moved by the user ([`arbor::camera::Camera::posed`]),
//! an integrator, an overlay and a sample budget. Its render runs in passes, each an ordinary
//! [`render_camera`] of one sample per pixel: first the whole frame at a quarter of the resolution (a
//! picture within milliseconds while the camera moves; skipped while full passes take under 40 ms),
//! then the overlay (one of the renderer's debug views, at full resolution), then full-resolution
//! passes with seeds 0, 1, 2, ... whose films are averaged, each average published as it lands, until
//! the budget is spent.
//!
//! A new view cancels the pass in flight through the renderer's own cancel flag (tiles not yet started
//! are skipped; a tile takes well under a millisecond at these sizes), so the worker moves on at once.
//! Images are published as 8-bit RGB on two watch channels (`render`, `overlay`) that any number of
//! requests can wait on; each publication is also announced as an event. The server never waits for a
//! pass: it only reads the last image published. The structure chart's benchmark holds the worker
//! between passes ([`Frames::quiet`]) so that neither measures the other's load.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::Instant;

use arbor::film::Film;
use arbor::integrator::DebugView;
use arbor::math::{Color, Vec3};
use arbor::render::{render_camera, RenderOptions, RenderStats};
use arbor::renderer::Renderer;
use arbor::tonemap::Tonemap;
use serde_json::json;
use tokio::sync::watch;

use crate::structures::{Events, Structures};

/// Frames smaller than this many pixels skip the low-resolution first pass.
const PREVIEW_MIN_PIXELS: u32 = 64 * 64;
/// Nor is there a preview while full passes of the view's size take less than this (milliseconds): the
/// full frame comes about as soon.
const PREVIEW_UNDER_MS: f64 = 40.0;

/// One view of the scene, as the page asks for it.
#[derive(Debug, Clone, PartialEq)]
pub struct ViewRequest {
    /// The scene's camera whose window, lens and settings the view keeps.
    pub camera: usize,
    /// Where the view looks from, along which direction, which way is up.
    pub eye: Vec3,
    /// Gaze direction (not necessarily unit).
    pub gaze: Vec3,
    /// Up direction.
    pub up: Vec3,
    /// Image size in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Whitted ray tracing or path tracing.
    pub renderer: Renderer,
    /// A debug view drawn as an overlay.
    pub overlay: Option<DebugView>,
    /// Samples per pixel to refine to.
    pub max_spp: u32,
}

/// A published image.
#[derive(Debug, Clone)]
pub struct Image {
    /// Publication number, increasing over both channels.
    pub seq: u64,
    /// The view it belongs to.
    pub view: u64,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major 8-bit RGB.
    pub rgb: Vec<u8>,
    /// Samples per pixel averaged (0 for the low-resolution preview).
    pub samples: u32,
    /// Wall time of the pass that made it, in milliseconds.
    pub render_ms: f64,
    /// Millions of rays per second in that pass.
    pub mrays: f64,
    /// Milliseconds spent turning the pass's film into this image (averaging, tone mapping, 8 bits).
    pub convert_ms: f64,
    /// The heatmap overlay's largest cost.
    pub heatmap_max: Option<u32>,
}

struct Job {
    version: u64,
    request: Option<ViewRequest>,
    cancel: Arc<AtomicBool>,
}

/// The render of the current view.
pub struct Frames {
    structures: Arc<Structures>,
    job: Mutex<Job>,
    wake: Condvar,
    seq: AtomicU64,
    /// The size and wall time of the last full-resolution pass.
    last_pass: Mutex<Option<((u32, u32), f64)>>,
    /// The last image of the view's render.
    pub render: watch::Sender<Option<Arc<Image>>>,
    /// The last overlay image.
    pub overlay: watch::Sender<Option<Arc<Image>>>,
    events: Events,
    /// Held by each pass from its render to its publication, and by whoever needs the cores quiet.
    quiet: Mutex<()>,
}

impl Frames {
    /// Starts the worker thread over `structures`' current scene.
    pub fn start(structures: Arc<Structures>, events: Events) -> Arc<Frames> {
        let frames = Arc::new(Frames {
            structures,
            job: Mutex::new(Job { version: 0, request: None, cancel: Arc::new(AtomicBool::new(false)) }),
            wake: Condvar::new(),
            seq: AtomicU64::new(0),
            last_pass: Mutex::new(None),
            render: watch::channel(None).0,
            overlay: watch::channel(None).0,
            events,
            quiet: Mutex::new(()),
        });
        let worker = Arc::downgrade(&frames);
        std::thread::spawn(move || work(worker));
        frames
    }

    /// Makes `request` the view, cancelling the render in flight; returns the view's number.
    pub fn set_view(&self, request: ViewRequest) -> u64 {
        let mut job = self.job.lock().unwrap_or_else(|e| e.into_inner());
        job.cancel.store(true, Ordering::Release);
        job.cancel = Arc::new(AtomicBool::new(false));
        job.version += 1;
        job.request = Some(request);
        self.wake.notify_all();
        job.version
    }

    /// Renders the current view again from its first pass (after the structure changed).
    pub fn restart(&self) {
        let request = self.current().map(|(_, r)| r);
        if let Some(r) = request {
            self.set_view(r);
        }
    }

    /// The current view and its number.
    pub fn current(&self) -> Option<(u64, ViewRequest)> {
        let job = self.job.lock().unwrap_or_else(|e| e.into_inner());
        job.request.clone().map(|r| (job.version, r))
    }

    /// Holds the worker between passes until the guard is dropped: a pass in flight ends (and is
    /// published) first, and no other starts meanwhile.
    pub fn quiet(&self) -> MutexGuard<'_, ()> {
        self.quiet.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Renders `request` (view `version`) pass by pass until it is done or `cancel` is set.
    fn run(&self, version: u64, request: &ViewRequest, cancel: &Arc<AtomicBool>) {
        let scene = self.structures.scene();
        let Some(base) = scene.cameras.get(request.camera) else { return };
        let (w, h) = (request.width, request.height);
        let posed = |w: u32, h: u32| base.posed(request.eye, request.gaze, request.up, w, h);
        let cam = posed(w, h);
        let opts = RenderOptions {
            spp: Some(1),
            cancel: Some(cancel.clone()),
            renderer: Some(request.renderer),
            ..Default::default()
        };
        let stale = || cancel.load(Ordering::Acquire);
        let publish = |channel: &watch::Sender<Option<Arc<Image>>>, name: &str, image: Image| {
            let event = json!({"type": "frame", "channel": name, "seq": image.seq, "view": version,
                "samples": image.samples, "width": image.width, "height": image.height,
                "render_ms": image.render_ms, "mrays": image.mrays, "convert_ms": image.convert_ms,
                "heatmap_max": image.heatmap_max});
            channel.send_replace(Some(Arc::new(image)));
            let _ = self.events.send(event.to_string());
        };
        let fail = |e: arbor::Error| {
            let _ = self.events.send(json!({"type": "error", "view": version, "error": e.to_string()}).to_string());
        };
        // A preview is worth its time only when a full pass is slow: the last one of this size decides.
        let last = *self.last_pass.lock().unwrap_or_else(|e| e.into_inner());
        let fast = last.is_some_and(|(size, ms)| size == (w, h) && ms < PREVIEW_UNDER_MS);
        if w * h >= PREVIEW_MIN_PIXELS && !fast {
            let _quiet = self.quiet();
            let small = posed((w / 4).max(1), (h / 4).max(1));
            match render_camera(&scene, &small, &opts, &|_, _| {}) {
                Ok((film, stats)) if !stale() => publish(
                    &self.render,
                    "render",
                    self.image(version, small.tonemap, &film, &stats, 0, Instant::now()),
                ),
                Ok(_) => return,
                Err(e) => return fail(e),
            }
        }
        if let Some(view) = request.overlay {
            let _quiet = self.quiet();
            match render_camera(&scene, &cam, &RenderOptions { debug: Some(view), ..opts.clone() }, &|_, _| {}) {
                Ok((film, stats)) if !stale() => {
                    let mut image = self.image(version, None, &film, &stats, 1, Instant::now());
                    image.heatmap_max = stats.heatmap_max;
                    publish(&self.overlay, "overlay", image);
                }
                Ok(_) => return,
                Err(e) => return fail(e),
            }
        }
        let mut sum = vec![Color::ZERO; w as usize * h as usize];
        for k in 0..request.max_spp {
            let _quiet = self.quiet();
            let (film, stats) =
                match render_camera(&scene, &cam, &RenderOptions { seed: k as u64, ..opts.clone() }, &|_, _| {}) {
                    Ok(r) if !stale() => r,
                    Ok(_) => return,
                    Err(e) => return fail(e),
                };
            *self.last_pass.lock().unwrap_or_else(|e| e.into_inner()) = Some(((w, h), stats.time.as_secs_f64() * 1e3));
            let start = Instant::now();
            sum.iter_mut().zip(&film.pixels).for_each(|(s, p)| *s += *p);
            let n = (k + 1) as f32;
            let mean = Film { width: w, height: h, pixels: sum.iter().map(|&s| s / n).collect() };
            publish(&self.render, "render", self.image(version, cam.tonemap, &mean, &stats, k + 1, start));
        }
    }

    /// `film` as a published image, tone-mapped by `tonemap` if any, as `arbor render` writes an 8-bit
    /// image; `start`: when its conversion began.
    fn image(
        &self,
        view: u64,
        tonemap: Option<Tonemap>,
        film: &Film,
        stats: &RenderStats,
        samples: u32,
        start: Instant,
    ) -> Image {
        let rgb = match tonemap {
            Some(t) => t.apply(film).to_rgb8(),
            None => film.to_rgb8(),
        };
        Image {
            seq: self.seq.fetch_add(1, Ordering::AcqRel) + 1,
            view,
            width: film.width,
            height: film.height,
            rgb,
            samples,
            render_ms: stats.time.as_secs_f64() * 1e3,
            mrays: stats.mrays_per_s(),
            convert_ms: start.elapsed().as_secs_f64() * 1e3,
            heatmap_max: None,
        }
    }
}

/// The worker: waits for a view newer than the last one rendered, renders it, and so on; ends when the
/// [`Frames`] is dropped.
fn work(frames: std::sync::Weak<Frames>) {
    let mut done = 0;
    loop {
        let Some(f) = frames.upgrade() else { return };
        let (version, request, cancel) = {
            let mut job = f.job.lock().unwrap_or_else(|e| e.into_inner());
            while job.version == done {
                // Woken by a new view, or now and then to see whether the server is gone.
                job = f
                    .wake
                    .wait_timeout(job, std::time::Duration::from_millis(500))
                    .unwrap_or_else(|e| e.into_inner())
                    .0;
                if Arc::strong_count(&f) == 1 {
                    return;
                }
            }
            (job.version, job.request.clone(), job.cancel.clone())
        };
        done = version;
        if let Some(r) = request {
            f.run(version, &r, &cancel);
        }
    }
}
