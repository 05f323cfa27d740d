//! `arbor render`: every camera of a scene to the image file it names, with a progress bar on a terminal
//! (plain lines otherwise), one summary line and one `Saved: PATH` line per image, and optionally the
//! same numbers as JSON (`--stats-json`). Farm slices (`--tile`, sample ranges) write partial EXRs
//! instead ([`crate::slice`]).
//!
//! SIGINT and SIGTERM stop the render between tiles: the image being rendered is not written (the
//! previous file, if any, stays as it was; images are written whole, by rename), and the command exits
//! 130 or 143. A second signal while the first is being honoured (e.g. during a long mesh load) exits at
//! once with the same code.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

use arbor::accel::{AccelKind, AccelSpec};
use arbor::farm::{write_partial, Partial};
use arbor::integrator::DebugView;
use arbor::light::environment::EnvMap;
use arbor::render::{render, render_sums, RenderOptions, RenderStats};
use arbor::scene::{check_limits, load_desc, parse_desc, Scene, SceneDesc, SceneLimits};
use clap::Args;
use serde_json::json;

use crate::progress::Progress;
use crate::slice::{identity, Slice, SliceArgs};
use crate::Failure;

/// The scene rendered when none is named: the repository's own Cornell box.
const EXAMPLE_NAME: &str = "cornell_box.xml";
const EXAMPLE: &str = include_str!("../../../examples/cornell_box.xml");

/// Arguments of `arbor render`.
#[derive(Args)]
pub struct RenderArgs {
    /// Scene file (.xml or .json). Without one, renders the built-in example Cornell box.
    pub scene: Option<PathBuf>,
    /// Folder for the images (created if missing); each camera's file name comes from the scene. For a
    /// slice (--tile, --sample-offset/--sample-count, or --crop with a .exr name): the partial EXR file.
    #[arg(short = 'o', long = "out", default_value = ".")]
    pub out: PathBuf,
    /// Acceleration structure: brute, octree, kdtree, bvh-median, bvh-sah, bvh-bottom-up.
    #[arg(long, default_value = "bvh-sah", value_parser = parse_accel)]
    pub accel: AccelKind,
    /// A build parameter of the structure, KEY=VALUE (repeatable; `arbor info --accels` lists them).
    #[arg(long = "accel-param", value_name = "KEY=VALUE")]
    pub accel_params: Vec<String>,
    /// Samples per pixel, overriding the scene's NumSamples.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub spp: Option<u32>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Environment map for rays that miss: a lat-long image, or a folder holding six cube faces
    /// (px nx py ny pz nz).
    #[arg(long)]
    pub env: Option<PathBuf>,
    /// Skip triangles facing away from camera rays (the course's back-face culling).
    #[arg(long, conflicts_with = "no_cull")]
    pub cull: bool,
    /// Never cull back faces, even when the scene asks for it.
    #[arg(long)]
    pub no_cull: bool,
    /// A debug view instead of the image: boxes[:DEPTH] (the structure's boxes at DEPTH, default 3, as
    /// wireframe over the render), heatmap (nodes visited + primitives tested per pixel, false colour,
    /// legend along the bottom, maximum printed), primid (a colour per primitive), normal.
    #[arg(long, value_name = "VIEW")]
    pub debug: Option<DebugView>,
    /// Render only the camera with this id.
    #[arg(long)]
    pub camera: Option<String>,
    /// Render only the window X0,Y0,X1,Y1 of each image (pixels X0..X1, Y0..Y1, top-left origin): the
    /// output is the window's size, and its pixels equal the same pixels of the full render.
    #[arg(long, value_name = "X0,Y0,X1,Y1", value_parser = parse_crop)]
    pub crop: Option<(u32, u32, u32, u32)>,
    #[command(flatten)]
    pub slice: SliceArgs,
    /// Write the render's numbers (scene, camera, size, window, samples, times, rays) as JSON to FILE.
    #[arg(long, value_name = "FILE")]
    pub stats_json: Option<PathBuf>,
    /// No progress bar and no summary lines (`Saved: PATH` lines stay).
    #[arg(short, long)]
    pub quiet: bool,
    /// Lift the limits on image size (16384 per side, 2^28 pixels), samples per pixel (65536), recursion
    /// depth (64) and pixels x samples (2^34) that guard against crafted scene files.
    #[arg(long)]
    pub no_limits: bool,
}

/// Parses `--accel`.
pub fn parse_accel(s: &str) -> Result<AccelKind, String> {
    s.parse()
}

/// Parses `--crop X0,Y0,X1,Y1`.
pub fn parse_crop(s: &str) -> Result<(u32, u32, u32, u32), String> {
    let v: Vec<u32> = s
        .split(',')
        .map(|p| p.trim().parse::<u32>().map_err(|_| format!("'{p}' is not a pixel coordinate")))
        .collect::<Result<_, _>>()?;
    match v[..] {
        [x0, y0, x1, y1] if x0 < x1 && y0 < y1 => Ok((x0, y0, x1, y1)),
        [_, _, _, _] => Err("the window is empty: need X0 < X1 and Y0 < Y1".into()),
        _ => Err(format!("expected X0,Y0,X1,Y1, got {} numbers", v.len())),
    }
}

/// Flags set by SIGINT and SIGTERM: `cancel` stops the render, the other two say which signal came.
struct Signals {
    cancel: Arc<AtomicBool>,
    int: Arc<AtomicBool>,
    term: Arc<AtomicBool>,
}

impl Signals {
    fn install() -> Result<Signals, Failure> {
        use signal_hook::consts::{SIGINT, SIGTERM};
        let s = Signals { cancel: Arc::default(), int: Arc::default(), term: Arc::default() };
        for (sig, which, code) in [(SIGINT, &s.int, 130), (SIGTERM, &s.term, 143)] {
            let ok = signal_hook::flag::register_conditional_shutdown(sig, code, Arc::clone(&s.cancel))
                .and_then(|_| signal_hook::flag::register(sig, Arc::clone(which)))
                .and_then(|_| signal_hook::flag::register(sig, Arc::clone(&s.cancel)));
            ok.map_err(|e| arbor::Error::Invalid(format!("cannot install a signal handler: {e}")))?;
        }
        Ok(s)
    }

    /// `Err(Interrupted)` once a signal came.
    fn check(&self) -> Result<(), Failure> {
        match (self.int.load(Ordering::SeqCst), self.term.load(Ordering::SeqCst)) {
            (true, _) => Err(Failure::Interrupted(130)),
            (_, true) => Err(Failure::Interrupted(143)),
            _ if self.cancel.load(Ordering::SeqCst) => Err(Failure::Interrupted(130)),
            _ => Ok(()),
        }
    }
}

/// The structure and parameters named on the command line.
pub fn accel_spec(kind: AccelKind, params: &[String]) -> Result<AccelSpec, Failure> {
    let spec = AccelSpec::new(kind).with_params(params.iter().map(String::as_str)).map_err(arbor::Error::Invalid)?;
    // Checked now, before any file is read.
    spec.check().map_err(arbor::Error::Invalid)?;
    Ok(spec)
}

/// Reads the scene named on the command line, or the built-in example.
pub fn read_scene(scene: &Option<PathBuf>) -> Result<SceneDesc, Failure> {
    Ok(match scene {
        Some(path) => load_desc(path)?,
        None => parse_desc(EXAMPLE, Path::new(EXAMPLE_NAME))?,
    })
}

/// The limits a scene is checked against: the defaults, or none with `--no-limits`.
pub fn limits(no_limits: bool) -> SceneLimits {
    if no_limits {
        SceneLimits::none()
    } else {
        SceneLimits::default()
    }
}

/// Runs `arbor render`.
pub fn run(args: RenderArgs) -> Result<(), Failure> {
    let signals = Signals::install()?;
    crate::set_threads(args.threads)?;
    let slice = Slice::from_args(&args.slice, args.crop, &args.out, args.debug.is_some())?;
    let t0 = Instant::now();
    let desc = read_scene(&args.scene)?;
    let parse_time = t0.elapsed();
    for w in &desc.warnings {
        if !args.quiet {
            eprintln!("warning: {w}");
        }
    }
    let cameras: Vec<usize> = match &args.camera {
        None => (0..desc.cameras.len()).collect(),
        Some(id) => {
            let found: Vec<usize> = (0..desc.cameras.len()).filter(|&i| &desc.cameras[i].id == id).collect();
            if found.is_empty() {
                let ids: Vec<&str> = desc.cameras.iter().map(|c| c.id.as_str()).collect();
                return Err(arbor::Error::Invalid(format!(
                    "{}: no camera with id '{id}' (cameras: {})",
                    crate::shown(&args.scene),
                    ids.join(", ")
                ))
                .into());
            }
            found
        }
    };
    if cameras.is_empty() {
        return Err(arbor::Error::Invalid(format!("{}: the scene has no camera", crate::shown(&args.scene))).into());
    }
    if slice.is_some() && cameras.len() != 1 {
        return Err(Failure::Usage(format!(
            "a slice renders one camera, but {} has {}: pick one with --camera ID",
            crate::shown(&args.scene),
            cameras.len()
        )));
    }
    check_limits(&desc, args.spp, &limits(args.no_limits))?;
    let env = args.env.as_deref().map(EnvMap::load).transpose()?;
    let spec = accel_spec(args.accel, &args.accel_params)?;
    let scene = Scene::build(desc, &spec, env)?;
    let cull = if args.cull {
        Some(true)
    } else if args.no_cull {
        Some(false)
    } else {
        None
    };
    let base = RenderOptions {
        spp: args.spp,
        cull_backfaces: cull,
        debug: args.debug,
        crop: args.crop,
        samples: None,
        cancel: Some(Arc::clone(&signals.cancel)),
    };
    if let Some((_, _, x1, y1)) = args.crop {
        if let Some(cam) = cameras.iter().map(|&c| &scene.cameras[c]).find(|c| x1 > c.width || y1 > c.height) {
            return Err(arbor::Error::Invalid(format!(
                "--crop reaches pixel ({x1}, {y1}) but camera '{}' is {}x{}",
                cam.id, cam.width, cam.height
            ))
            .into());
        }
    }
    let mut records = Vec::new();
    for &c in &cameras {
        let cam = &scene.cameras[c];
        let spp = args.spp.unwrap_or(cam.num_samples).max(1);
        let (path, stats, window) = match &slice {
            Some(s) => {
                let opts = RenderOptions { crop: s.window(cam)?, samples: Some(s.samples(spp)?), ..base.clone() };
                let scene_bytes = match &args.scene {
                    Some(p) => std::fs::read(p).map_err(|e| arbor::Error::io(p, e))?,
                    None => EXAMPLE.as_bytes().to_vec(),
                };
                let id = identity(&scene_bytes, &cam.id, spp, cull, args.env.as_deref());
                let bar = Progress::new(args.quiet, pixels(opts.crop, cam.width, cam.height), &cam.image_name);
                signals.check()?;
                let (sums, stats) = render_sums(&scene, c, &opts, &|done, total| bar.set(done, total));
                bar.finish();
                signals.check()?;
                let window = sums.window;
                write_partial(&s.out, &Partial { identity: id, camera: cam.id.clone(), sums })?;
                (s.out.clone(), stats, window)
            }
            None => {
                let path = args.out.join(&cam.image_name);
                let bar = Progress::new(args.quiet, pixels(base.crop, cam.width, cam.height), &cam.image_name);
                signals.check()?;
                let (film, stats) = render(&scene, c, &base, &|done, total| bar.set(done, total));
                bar.finish();
                // A signal during the render leaves an incomplete film: never written.
                signals.check()?;
                arbor::image_io::write_image(&path, &film)?;
                (path, stats, arbor::render::crop_window(base.crop, cam.width, cam.height))
            }
        };
        if !args.quiet {
            summary(&args, &scene, &path, window, &stats, parse_time);
        }
        say!("Saved: {}", path.display());
        if let Some(max) = stats.heatmap_max {
            // Printed even with --quiet: without it the heatmap's colours have no scale.
            say!("heatmap maximum {max} (nodes visited + primitives tested) for {}", path.display());
        }
        records.push(json!({
            "scene": crate::shown(&args.scene),
            "camera": cam.id,
            "image": path.display().to_string(),
            "width": cam.width,
            "height": cam.height,
            "window": [window.0, window.1, window.2, window.3],
            "spp": stats.spp,
            "samples": [stats.samples.0, stats.samples.1],
            "accel": args.accel.to_string(),
            "parse_ms": (parse_time + scene.geometry.counts.mesh_load).as_secs_f64() * 1e3,
            "build_ms": scene.build_time.as_secs_f64() * 1e3,
            "render_ms": stats.time.as_secs_f64() * 1e3,
            "rays": stats.rays,
            "mrays_per_s": stats.mrays_per_s(),
            "threads": rayon::current_num_threads(),
            "triangles": scene.geometry.counts.triangles,
        }));
    }
    if let Some(file) = &args.stats_json {
        let text = serde_json::to_string_pretty(&json!({ "images": records }))
            .map_err(|e| arbor::Error::Invalid(format!("cannot encode the statistics: {e}")))?;
        std::fs::write(file, text + "\n").map_err(|e| arbor::Error::io(file, e))?;
    }
    // A signal during the last write let that (atomic) write finish; the run still reports it.
    signals.check()
}

/// Pixels in the window of a `w` x `h` frame.
fn pixels(crop: Option<(u32, u32, u32, u32)>, w: u32, h: u32) -> u64 {
    let (x0, y0, x1, y1) = arbor::render::crop_window(crop, w, h);
    (x1 - x0) as u64 * (y1 - y0) as u64
}

/// The two summary lines of one image.
fn summary(
    args: &RenderArgs,
    scene: &Scene,
    path: &Path,
    window: (u32, u32, u32, u32),
    stats: &RenderStats,
    parse_time: std::time::Duration,
) {
    let g = &scene.geometry.counts;
    let samples = match stats.samples {
        (0, k1) if k1 == stats.spp => format!("{} spp", stats.spp),
        (k0, k1) => format!("samples {k0}..{k1} of {} spp", stats.spp),
    };
    say!(
        "{}  {}x{}  {samples}  parse {:.1} ms  build {:.1} ms ({}, {} triangles, {} spheres, {} planes)  \
         render {:.1} ms  {:.2} M rays  {:.2} Mrays/s",
        path.display(),
        window.2 - window.0,
        window.3 - window.1,
        (parse_time + g.mesh_load).as_secs_f64() * 1e3,
        scene.build_time.as_secs_f64() * 1e3,
        args.accel,
        g.triangles,
        g.spheres,
        g.planes,
        stats.time.as_secs_f64() * 1e3,
        stats.rays as f64 / 1e6,
        stats.mrays_per_s()
    );
    let s = scene.geometry.accel_stats();
    say!(
        "  structure {}: {} nodes, {} leaves, depth max {} mean {:.1}{}",
        s.kind,
        s.nodes,
        s.leaves,
        s.max_depth,
        s.mean_depth,
        args.debug.map_or(String::new(), |v| format!("; debug view {v}"))
    );
}
