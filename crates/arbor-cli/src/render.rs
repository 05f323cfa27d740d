//! `arbor render`: every camera of a scene to the image file it names, with a progress bar on a terminal
//! (plain lines otherwise), one summary line per image, and optionally the same numbers as JSON
//! (`--stats-json`). Farm slices (`--tile`, sample ranges) write partial EXRs instead ([`crate::slice`]).
//!
//! Every output path is worked out and checked before the scene is built ([`crate::outputs`]), and the
//! memory an image needs is reserved before it is rendered (exit 4 when there is not enough). The files
//! of a run (each camera's image, the PNG beside an HDR one, the statistics) are encoded as their render
//! ends and written together after the last one, all or none ([`arbor::image_io::write_files`]), then
//! listed as `Saved: PATH` lines: a run that fails at its third camera leaves no image of its first two
//! and every older file as it was. The price is memory: the encoded files wait (reserved up front,
//! [`crate::memory::reserve_run`]). SIGINT and SIGTERM stop the command at any stage
//! ([`crate::signals`]): nothing of the run is written, and the command exits 130 or 143.

use std::path::{Path, PathBuf};
use std::time::Instant;

use arbor::accel::{AccelConfig, AccelKind};
use arbor::farm::{encode_partial, Partial};
use arbor::integrator::DebugView;
use arbor::light::environment::EnvMap;
use arbor::render::{render, render_sums, RenderOptions, RenderStats};
use arbor::renderer::Renderer;
use arbor::scene::{check_limits, load_desc, parse_desc, Scene, SceneDesc, SceneLimits};
use clap::Args;
use serde_json::json;

use crate::outputs::hdr_preview;
use crate::progress::Progress;
use crate::signals::{Signals, Stage};
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
    /// Folder for the images (created if missing); each camera's file name comes from the scene. A name
    /// ending in an image extension (.png, .ppm, .exr, .hdr, .jpg, .jpeg) is the image of a one-camera
    /// scene. An .exr or .hdr image holds radiance in the scene's units (255 is an 8-bit image's white in
    /// METU files) and gets its tone-mapped PNG beside it (x.exr: x.png), which replaces a file of that
    /// name. Every file of the run is written after the last render, all together, or none when the run
    /// fails. For a slice (--tile, --sample-offset/--sample-count, or --crop with a .exr name): the partial
    /// EXR.
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
    /// Seed of every random choice (pixel samples, lens, time, area lights, glossy rays): the same seed
    /// gives the same image on any number of threads, tiles or slices; another seed, independent noise.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    #[command(flatten)]
    pub integrator: crate::integrator::IntegratorArgs,
    #[command(flatten)]
    pub threads: crate::threads::ThreadsArg,
    /// Environment map for rays that miss: a lat-long image, or a folder holding six cube faces
    /// (px nx py ny pz nz).
    #[arg(long)]
    pub env: Option<PathBuf>,
    /// Cull back faces of camera rays: skip the triangles and planes they meet from behind (the course's
    /// back-face culling). Without --cull or --no-cull the scene decides: its BackfaceCulling element,
    /// else culling for the 2025 JSON form (its official images are culled) and none for XML and NYU
    /// JSON files (an XML image most of whose camera rays meet back faces gets a warning naming
    /// --cull: the XML form does not say its year, and some years' images are culled).
    #[arg(long, conflicts_with = "no_cull")]
    pub cull: bool,
    /// Never cull back faces, even when the scene or its form (2025 JSON) asks for it.
    #[arg(long)]
    pub no_cull: bool,
    /// A debug view instead of the image: boxes[:DEPTH] (wireframe over the render of the nodes DEPTH
    /// levels below the root of each structure: the top level's over the objects and each mesh's own;
    /// 0 is the root's box, the default 3; the levels are those the render summary's and `arbor info`'s
    /// depths count, a BVH's binary tree's, so DEPTH = its depth max shows the deepest leaves), heatmap (nodes visited + primitives tested per pixel, false colour,
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
    /// No progress and no summary lines (`Saved: PATH` lines and warnings stay); twice (-qq) also no
    /// warnings.
    #[arg(short, long, action = clap::ArgAction::Count)]
    pub quiet: u8,
    /// No warnings (unknown elements, unused properties, suspicious cameras and scenes).
    #[arg(long)]
    pub no_warnings: bool,
    /// Lift the limits on image size (16384 per side, 2^28 pixels), samples per pixel (65536), recursion
    /// depth (64), pixels x samples (2^34) and the pixels of each image the scene reads (2^26: textures,
    /// environment maps, cube faces, --env) that guard against crafted scene files.
    #[arg(long)]
    pub no_limits: bool,
}

/// Parses `--accel`.
pub fn parse_accel(s: &str) -> Result<AccelKind, String> {
    s.parse().map_err(|e: arbor::accel::ConfigError| e.to_string())
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

/// The structure and parameters named on the command line; a parameter that does not apply, does not
/// read or lies outside its range is a usage error, found before any file is read.
pub fn accel_spec(kind: AccelKind, params: &[String]) -> Result<AccelConfig, Failure> {
    AccelConfig::from(kind).with_pairs(params.iter().map(String::as_str)).map_err(|e| Failure::Usage(e.to_string()))
}

/// Reads the scene named on the command line, or the built-in example.
pub fn read_scene(scene: &Option<PathBuf>) -> Result<SceneDesc, Failure> {
    Ok(match scene {
        Some(path) if is_mesh_file(path) => {
            let msg = format!(
                "this is a mesh file, not a scene (.xml or .json); `arbor bench {}` takes meshes",
                path.display()
            );
            return Err(arbor::Error::input(arbor::Location::file(path), msg).into());
        }
        Some(path) => load_desc(path)?,
        None => parse_desc(EXAMPLE, Path::new(EXAMPLE_NAME))?,
    })
}

/// True for the extensions of the mesh formats Arbor reads.
pub fn is_mesh_file(path: &Path) -> bool {
    let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
    matches!(ext.as_deref(), Some("ply" | "obj" | "off"))
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
pub fn run(args: RenderArgs, signals: &Signals) -> Result<(), Failure> {
    args.threads.apply()?;
    let slice = Slice::from_args(&args.slice, args.crop, &args.out, args.debug.is_some())?;
    // Checked before any file is read.
    let spec = accel_spec(args.accel, &args.accel_params)?;
    args.integrator.renderer(Renderer::Whitted).map_err(Failure::Usage)?;
    let t0 = Instant::now();
    let desc = read_scene(&args.scene)?;
    let parse_time = t0.elapsed();
    let cameras = chosen_cameras(&args, &desc)?;
    if args.quiet < 2 && !args.no_warnings {
        for w in crate::warnings::scene_warnings(&desc) {
            eprintln!("warning: {w}");
        }
        for cam in cameras.iter().map(|&c| &desc.cameras[c]) {
            let renderer = args.integrator.renderer(cam.renderer).map_err(Failure::Usage)?.unwrap_or(cam.renderer);
            if let Some(w) = crate::warnings::dark_path_tracing(&desc, cam, renderer, args.env.is_some()) {
                eprintln!("warning: {w}");
            }
        }
    }
    if slice.is_some() && cameras.len() != 1 {
        return Err(Failure::Usage(format!(
            "a slice renders one camera, but {} has {}: pick one with --camera ID",
            crate::shown(&args.scene),
            cameras.len()
        )));
    }
    let limits = limits(args.no_limits);
    check_limits(&desc, args.spp, &limits)?;
    if let Some((_, _, x1, y1)) = args.crop {
        if let Some(cam) = cameras.iter().map(|&c| &desc.cameras[c]).find(|c| x1 > c.width || y1 > c.height) {
            return Err(arbor::Error::Invalid(format!(
                "--crop reaches pixel ({x1}, {y1}) but camera '{}' is {}x{}",
                cam.id, cam.width, cam.height
            ))
            .into());
        }
    }
    let targets = match &slice {
        Some(s) => {
            crate::outputs::check_writable(&s.out, true)?;
            vec![s.out.clone()]
        }
        None => {
            let cams: Vec<_> = cameras.iter().map(|&c| &desc.cameras[c]).collect();
            // A debug view is written as it is, with no tone-mapped PNG beside it.
            crate::outputs::image_targets(&args.out, &cams, args.debug.is_none())?
        }
    };
    if let Some(file) = &args.stats_json {
        crate::outputs::check_writable(file, false)?;
    }
    if slice.is_none() {
        let cams: Vec<_> = cameras.iter().map(|&c| &desc.cameras[c]).collect();
        crate::memory::reserve_run(&cams, &targets, args.crop, args.debug.is_none())?;
    }
    let env = args.env.as_deref().map(|p| EnvMap::load(p, &limits.images)).transpose()?;
    let camera_locs: Vec<_> = desc.cameras.iter().map(|c| c.loc.clone()).collect();
    let scene = Scene::build_within(desc, &spec, env, &limits.images)?;
    let warn = args.quiet < 2 && !args.no_warnings;
    let whitted = args.debug.is_none_or(|v| v.shades())
        && cameras.iter().any(|&c| {
            let own = scene.cameras[c].renderer;
            args.integrator.renderer(own).is_ok_and(|r| r.unwrap_or(own) == Renderer::Whitted)
        });
    if let Some(w) = crate::warnings::tree_warning(&crate::shown(&args.scene), &scene).filter(|_| warn && whitted) {
        eprintln!("warning: {w}");
    }
    signals.enter(Stage::Render);
    let cull = if args.cull {
        Some(true)
    } else if args.no_cull {
        Some(false)
    } else {
        None
    };
    if args.quiet < 2 && !args.no_warnings {
        for w in crate::warnings::back_faces(&scene, &cameras, &camera_locs, cull) {
            eprintln!("warning: {w}");
        }
    }
    let base = RenderOptions {
        spp: args.spp,
        cull_backfaces: cull,
        debug: args.debug,
        crop: args.crop,
        samples: None,
        cancel: Some(signals.cancel_flag()),
        seed: args.seed,
        renderer: None,
        sampler: args.integrator.sampler.into(),
        heatmap_scale: None,
    };
    let mut records = Vec::new();
    // Every file of the run, encoded, written together after the last render: all of them or none, so
    // that a run that fails (an error, a signal, too little memory) leaves every older file as it was.
    let mut files: Vec<(PathBuf, Vec<u8>)> = Vec::new();
    for (&c, target) in cameras.iter().zip(targets) {
        let cam = &scene.cameras[c];
        let spp = args.spp.unwrap_or(cam.num_samples).max(1);
        let renderer = args.integrator.renderer(cam.renderer).map_err(Failure::Usage)?;
        if args.quiet < 2 && !args.no_warnings {
            if let Some(w) = args.integrator.roulette_unused(cam.renderer, &cam.id) {
                eprintln!("warning: {w}");
            }
        }
        let base = RenderOptions { renderer, ..base.clone() };
        // A debug view is written as it is.
        let tonemap = if args.debug.is_some() { None } else { cam.tonemap };
        let (path, stats, window) = match &slice {
            Some(s) => {
                let opts = RenderOptions { crop: s.window(cam)?, samples: Some(s.samples(spp)?), ..base.clone() };
                let scene_bytes = match &args.scene {
                    Some(p) => std::fs::read(p).map_err(|e| arbor::Error::io(p, e))?,
                    None => EXAMPLE.as_bytes().to_vec(),
                };
                let id = identity(&scene_bytes, &cam.id, spp, args.env.as_deref(), &base);
                let window = arbor::render::crop_window(opts.crop, cam.width, cam.height);
                crate::memory::reserve_for(cam.width, cam.height, window, true)?;
                let bar = Progress::new(args.quiet > 0, pixels(opts.crop, cam.width, cam.height), &cam.image_name);
                signals.check()?;
                let (sums, stats) = render_sums(&scene, c, &opts, &|done, total| bar.set(done, total))?;
                bar.finish();
                signals.check()?;
                let part = Partial { identity: id, camera: cam.id.clone(), tonemap, sums };
                files.push((target.clone(), encode_partial(&target, &part)?));
                (target, stats, window)
            }
            None => {
                let window = arbor::render::crop_window(base.crop, cam.width, cam.height);
                crate::memory::reserve_for(cam.width, cam.height, window, false)?;
                let bar = Progress::new(args.quiet > 0, pixels(base.crop, cam.width, cam.height), &cam.image_name);
                signals.check()?;
                let (film, stats) = render(&scene, c, &base, &|done, total| bar.set(done, total))?;
                bar.finish();
                // A signal during the render leaves an incomplete film: never written.
                signals.check()?;
                let (tonemap, unit) = if args.debug.is_some() {
                    (None, 1.0)
                } else {
                    (tonemap.or_else(|| hdr_preview(&target, scene.radiance_scale)), scene.radiance_scale)
                };
                files.extend(arbor::image_io::encode_outputs(&target, &film, unit, tonemap.as_ref())?);
                (target, stats, window)
            }
        };
        if args.quiet == 0 {
            summary(&args, &scene, &path, window, &stats, parse_time);
        }
        if let Some(w) =
            crate::warnings::capped_warning(&crate::shown(&args.scene), &cam.id, &stats, window_pixels(window))
                .filter(|_| warn)
        {
            eprintln!("warning: {w}");
        }
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
            "traversal_share": stats.traversal_share(),
            "kernel": arbor::accel::bvh::query_kernel(),
            "threads": rayon::current_num_threads(),
            "triangles": scene.geometry.counts.triangles,
        }));
    }
    let images = files.len();
    if let Some(file) = &args.stats_json {
        let text = serde_json::to_string_pretty(&json!({ "images": records }))
            .map_err(|e| arbor::Error::Invalid(format!("cannot encode the statistics: {e}")))?;
        files.push((file.clone(), (text + "\n").into_bytes()));
    }
    signals.writing(|| arbor::image_io::write_files(&files))?;
    for (path, _) in &files[..images] {
        say!("Saved: {}", path.display());
    }
    // A signal during the write let that (atomic) write finish; the run still reports it.
    signals.check()
}

/// The cameras to render: all, or the one `--camera` names.
fn chosen_cameras(args: &RenderArgs, desc: &SceneDesc) -> Result<Vec<usize>, Failure> {
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
    Ok(cameras)
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
         render {:.1} ms  {:.2} M rays  {:.2} Mrays/s{}",
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
        stats.mrays_per_s(),
        stats.traversal_share().map_or(String::new(), |f| format!("  traversal {:.0}% of CPU time", f * 100.0))
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

/// Pixels in a window `(x0, y0, x1, y1)`.
fn window_pixels((x0, y0, x1, y1): (u32, u32, u32, u32)) -> u64 {
    (x1 - x0) as u64 * (y1 - y0) as u64
}
