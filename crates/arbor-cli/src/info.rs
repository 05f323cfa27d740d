//! `arbor info`: what a scene contains and what its acceleration structure looks like once built.

use std::path::PathBuf;

use arbor::accel::AccelKind;
use arbor::scene::{LightDesc, MaterialKind, MeshSource, Scene, ShapeDesc};
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
    /// Lift the limits on image size, samples and recursion depth (as `arbor render --no-limits`).
    #[arg(long)]
    pub no_limits: bool,
}

/// Runs `arbor info`.
pub fn run(args: InfoArgs) -> Result<(), Failure> {
    if args.accels {
        for kind in AccelKind::ALL {
            say!("{kind}");
            for (key, what) in kind.param_keys() {
                say!("    --accel-param {key}=VALUE    {what}");
            }
        }
        return Ok(());
    }
    let desc = crate::render::read_scene(&args.scene)?;
    arbor::scene::check_limits(&desc, None, &crate::render::limits(args.no_limits))?;
    say!("scene      {}", crate::shown(&args.scene));
    say!(
        "settings   background {}  ambient {}  max depth {}  shadow epsilon {}",
        desc.background,
        desc.ambient,
        desc.max_depth,
        desc.shadow_epsilon
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
        }
    }
    for m in &desc.materials {
        let kind = match m.kind {
            MaterialKind::BlinnPhong => "blinn-phong",
            MaterialKind::Mirror { .. } => "mirror",
            MaterialKind::Conductor { .. } => "conductor",
            MaterialKind::Dielectric { .. } => "dielectric",
            MaterialKind::Transparent { .. } => "transparent (legacy)",
        };
        say!("material {}  {kind}", m.id);
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
    for w in crate::warnings::scene_warnings(&desc) {
        say!("warning    {w}");
    }
    let spec = crate::render::accel_spec(args.accel, &args.accel_params)?;
    let scene = Scene::build(desc, &spec, None)?;
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
