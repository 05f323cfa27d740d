//! `arbor render`: every camera of a scene to the image file it names, with a progress bar on a terminal
//! and one summary line per image.
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
use arbor::integrator::DebugView;
use arbor::light::environment::EnvMap;
use arbor::render::{render, RenderOptions};
use arbor::scene::{check_limits, load_desc, parse_desc, Scene, SceneDesc, SceneLimits};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};

use crate::Failure;

/// The scene rendered when none is named: the repository's own Cornell box.
const EXAMPLE_NAME: &str = "cornell_box.xml";
const EXAMPLE: &str = include_str!("../../../examples/cornell_box.xml");

/// Arguments of `arbor render`.
#[derive(Args)]
pub struct RenderArgs {
    /// Scene file (.xml or .json). Without one, renders the built-in example Cornell box.
    pub scene: Option<PathBuf>,
    /// Folder for the images (created if missing); each camera's file name comes from the scene.
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
    /// No progress bar and no summary lines.
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
    check_limits(&desc, args.spp, &limits(args.no_limits))?;
    let env = args.env.as_deref().map(EnvMap::load).transpose()?;
    let spec = accel_spec(args.accel, &args.accel_params)?;
    let scene = Scene::build(desc, &spec, env)?;
    let opts = RenderOptions {
        spp: args.spp,
        cull_backfaces: if args.cull {
            Some(true)
        } else if args.no_cull {
            Some(false)
        } else {
            None
        },
        debug: args.debug,
        crop: args.crop,
        cancel: Some(Arc::clone(&signals.cancel)),
    };
    if let Some((_, _, x1, y1)) = args.crop {
        if let Some(cam) = cameras.iter().map(|&c| &scene.desc.cameras[c]).find(|c| x1 > c.width || y1 > c.height) {
            return Err(arbor::Error::Invalid(format!(
                "--crop reaches pixel ({x1}, {y1}) but camera '{}' is {}x{}",
                cam.id, cam.width, cam.height
            ))
            .into());
        }
    }
    for &c in &cameras {
        let cam = &scene.desc.cameras[c];
        let path = args.out.join(&cam.image_name);
        let bar = progress_bar(args.quiet, cam.width as u64 * cam.height as u64, &cam.image_name);
        signals.check()?;
        let (film, stats) = render(&scene, c, &opts, &|done, _| bar.set_position(done));
        bar.finish_and_clear();
        // A signal during the render leaves an incomplete film: never written.
        signals.check()?;
        arbor::image_io::write_image(&path, &film)?;
        if !args.quiet {
            let g = &scene.geometry.counts;
            say!(
                "{}  {}x{}  {} spp  parse {:.1} ms  build {:.1} ms ({}, {} triangles, {} spheres, {} planes)  \
                 render {:.1} ms  {:.2} M rays  {:.2} Mrays/s",
                path.display(),
                film.width,
                film.height,
                stats.spp,
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
        if let Some(max) = stats.heatmap_max {
            // Printed even with --quiet: without it the heatmap's colours have no scale.
            say!("heatmap maximum {max} (nodes visited + primitives tested) for {}", path.display());
        }
    }
    // A signal during the last write let that (atomic) write finish; the run still reports it.
    signals.check()
}

/// A bar on standard error, drawn only on a terminal (indicatif hides it otherwise).
fn progress_bar(quiet: bool, len: u64, name: &str) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len);
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {percent:>3}% {elapsed_precise} (eta {eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    bar.set_message(name.to_string());
    bar
}
