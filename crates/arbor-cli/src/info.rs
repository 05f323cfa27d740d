//! `arbor info`: what a scene contains and what its acceleration structure looks like once built.

use std::path::PathBuf;

use arbor::accel::{AccelConfig, AccelKind};
use arbor::renderer::{PathOptions, Renderer, Roulette};
use arbor::scene::{BrdfDesc, BrdfKind, LightDesc, MaterialKind, MeshSource, Scene, ShapeDesc};
use clap::Args;

use crate::Failure;

/// Arguments of `arbor info`.
#[derive(Args)]
pub struct InfoArgs {
    /// Scene file (.xml or .json). Without one, describes the built-in example.
    pub scene: Option<PathBuf>,
    /// Acceleration structure to build and report on.
    #[arg(long, default_value = "bvh-sah", value_parser = crate::render::parse_accel)]
    pub accel: AccelKind,
    /// A build parameter of the structure, KEY=VALUE (repeatable).
    #[arg(long = "accel-param", value_name = "KEY=VALUE")]
    pub accel_params: Vec<String>,
    /// List the acceleration structures and their parameters, and exit.
    #[arg(long)]
    pub accels: bool,
    /// Lift the limits on image size, samples, recursion depth and the pixels of the images a scene reads
    /// (as `arbor render --no-limits`).
    #[arg(long)]
    pub no_limits: bool,
}

/// A path-traced camera's options as `arbor info` lists them, its roulette spelt out.
fn describe_path_tracer(o: PathOptions) -> String {
    let mut words = vec!["path tracing"];
    for (on, word) in
        [(o.importance_sampling, "importance sampling"), (o.next_event, "next event estimation"), (o.mis, "MIS")]
    {
        if on {
            words.push(word);
        }
    }
    let roulette = match o.roulette {
        Roulette::Off => "paths end at MaxRecursionDepth",
        Roulette::Course => {
            "the course's Russian roulette (biased: brighter than the converged answer; --roulette unbiased for \
             Arbor's)"
        }
        Roulette::Unbiased => "Arbor's unbiased Russian roulette",
    };
    let glass = if o.split_refraction {
        "; both lobes of refractive surfaces followed, as the course's renderer does"
    } else {
        ""
    };
    format!("{}; {roulette}{glass}", words.join(", "))
}

/// Runs `arbor info`.
pub fn run(args: InfoArgs) -> Result<(), Failure> {
    if args.accels {
        list_accels();
        return Ok(());
    }
    let spec = crate::render::accel_spec(args.accel, &args.accel_params)?;
    let desc = crate::render::read_scene(&args.scene)?;
    let limits = crate::render::limits(args.no_limits);
    arbor::scene::check_limits(&desc, None, &limits)?;
    say!("scene      {}", crate::shown(&args.scene));
    say!(
        "settings   background {}  ambient {}  max depth {}  shadow epsilon {}  back-face culling {}",
        desc.background,
        desc.ambient,
        desc.max_depth,
        desc.shadow_epsilon,
        match desc.cull_backfaces {
            Some(true) => "on",
            Some(false) => "off",
            None => "off (unless render --cull)",
        }
    );
    for c in &desc.cameras {
        say!(
            "camera {}   {}x{}  {} spp  -> {}{}",
            c.id,
            c.width,
            c.height,
            c.num_samples,
            c.image_name,
            if c.orthographic { "  (orthographic)" } else { "" }
        );
        if let Renderer::PathTracing(o) = c.renderer {
            say!("  renderer {}", describe_path_tracer(o));
        }
        if let Some(t) = &c.tonemap {
            say!(
                "  tonemap  {:?}  key {}  burn {}%  saturation {}  gamma {}",
                t.operator,
                t.key,
                t.burn_percent,
                t.saturation,
                t.gamma
            );
        }
    }
    for l in &desc.lights {
        match l {
            LightDesc::Point { position, intensity } => {
                say!("light      point at {position}, intensity {intensity}")
            }
            LightDesc::Area { position, size, radiance, .. } => {
                say!("light      area {size}x{size} at {position}, radiance {radiance}")
            }
            LightDesc::Directional { direction, radiance } => {
                say!("light      directional along {direction}, radiance {radiance}")
            }
            LightDesc::Spot { position, direction, intensity, coverage_deg, falloff_deg } => {
                say!(
                    "light      spot at {position} along {direction}, intensity {intensity}, coverage {coverage_deg}°, \
                     fall-off {falloff_deg}°"
                )
            }
        }
    }
    if let Some(env) = &desc.environment {
        let form = if desc.environment_probe { "light probe" } else { "lat-long" };
        say!("light      environment {} ({form})", env.display());
    }
    for m in &desc.materials {
        let kind = match m.kind {
            MaterialKind::BlinnPhong => "blinn-phong",
            MaterialKind::Mirror { .. } => "mirror",
            MaterialKind::Conductor { .. } => "conductor",
            MaterialKind::Dielectric { .. } => "dielectric",
            MaterialKind::Transparent { .. } => "transparent (legacy)",
        };
        match &m.brdf {
            Some(b) => say!("material {}  {kind}, BRDF {}", m.id, brdf_name(b)),
            None => say!("material {}  {kind}", m.id),
        }
    }
    for o in &desc.objects {
        let what = match &o.shape {
            ShapeDesc::Mesh { source: MeshSource::Inline(m), smooth } => {
                format!("mesh, {} triangles inline{}", m.len(), if *smooth { ", smooth" } else { "" })
            }
            ShapeDesc::Mesh { source: MeshSource::File(p), smooth } => {
                format!("mesh from {}{}", p.display(), if *smooth { ", smooth" } else { "" })
            }
            ShapeDesc::Sphere { radius, .. } => format!("sphere, radius {radius}"),
            ShapeDesc::Plane { .. } => "plane".to_string(),
            ShapeDesc::Instance { base } => format!("instance of {}", desc.objects[*base].name),
        };
        say!("object     {}: {what}", o.name);
    }
    let dark = desc.cameras.iter().filter_map(|c| crate::warnings::dark_path_tracing(&desc, c, c.renderer, false));
    for w in crate::warnings::scene_warnings(&desc).into_iter().chain(dark) {
        say!("warning    {w}");
    }
    let camera_locs: Vec<_> = desc.cameras.iter().map(|c| c.loc.clone()).collect();
    let scene = Scene::build_within(desc, &spec, None, &limits.images)?;
    let cameras: Vec<usize> = (0..scene.cameras.len()).collect();
    for w in crate::warnings::back_faces(&scene, &cameras, &camera_locs, None) {
        say!("warning    {w}");
    }
    let g = &scene.geometry.counts;
    say!(
        "geometry   {} triangles ({} degenerate), {} spheres, {} planes; bounds {} .. {}; meshes read in {:.1} ms",
        g.triangles,
        g.degenerate,
        g.spheres,
        g.planes,
        scene.geometry.bounds().min,
        scene.geometry.bounds().max,
        g.mesh_load.as_secs_f64() * 1e3
    );
    let s = scene.geometry.accel_stats();
    say!("structure  {} over {} primitives, built in {:.1} ms", s.kind, s.primitives, s.build_time.as_secs_f64() * 1e3);
    say!("           {} nodes, {} leaves; leaf depth max {}, mean {:.2}", s.nodes, s.leaves, s.max_depth, s.mean_depth);
    say!(
        "           {:.2} primitives per non-empty leaf, {:.3} references per primitive",
        s.mean_leaf_prims,
        s.refs_per_prim
    );
    say!("           SAH cost {:.2}, {:.1} KiB", s.sah_cost, s.bytes as f64 / 1024.0);
    Ok(())
}

/// `arbor info --accels`: every structure, and under it one line per parameter with its range and
/// default, in columns aligned across all structures.
fn list_accels() {
    let rows: Vec<(AccelKind, Vec<[String; 4]>)> = AccelKind::ALL
        .iter()
        .map(|&kind| {
            let defaults = AccelConfig::from(kind);
            let rows = kind
                .params()
                .iter()
                .map(|p| {
                    let default = defaults.get(p.key).map_or_else(String::new, |v| v.to_string());
                    [format!("{}=VALUE", p.key), p.range.to_string(), default, p.about.to_string()]
                })
                .collect();
            (kind, rows)
        })
        .collect();
    let width = |col: usize| rows.iter().flat_map(|(_, r)| r).map(|r| r[col].len()).max().unwrap_or(0);
    const HEADING: &str = "structure / --accel-param";
    // Parameter lines are indented by 4 under their structure's name.
    let key_w = width(0).max(HEADING.len() - 4);
    let (range_w, default_w) = (width(1), width(2).max("default".len()));
    say!("{HEADING:<w$}  {:<range_w$}  {:<default_w$}  meaning", "range", "default", w = key_w + 4);
    for (kind, params) in &rows {
        if params.is_empty() {
            say!("{kind}  (no parameters)");
            continue;
        }
        say!("{kind}");
        for [key, range, default, about] in params {
            say!("    {key:<key_w$}  {range:<range_w$}  {default:<default_w$}  {about}");
        }
    }
}

/// A BRDF as `info` shows it: the model, its options, the exponent.
fn brdf_name(b: &BrdfDesc) -> String {
    let normalized = |n: bool| if n { " normalized" } else { "" };
    let model = match b.kind {
        BrdfKind::OriginalPhong => "OriginalPhong".to_string(),
        BrdfKind::ModifiedPhong { normalized: n } => format!("ModifiedPhong{}", normalized(n)),
        BrdfKind::OriginalBlinnPhong => "OriginalBlinnPhong".to_string(),
        BrdfKind::ModifiedBlinnPhong { normalized: n } => format!("ModifiedBlinnPhong{}", normalized(n)),
        BrdfKind::TorranceSparrow { kd_fresnel, eta, k } => {
            format!("TorranceSparrow (n {eta}, k {k}{})", if kd_fresnel { ", kdfresnel" } else { "" })
        }
    };
    format!("{model}, exponent {}", b.exponent)
}
