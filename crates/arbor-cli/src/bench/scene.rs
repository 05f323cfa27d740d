//! `arbor bench INPUT`: builds every chosen structure over one scene or mesh, traces the same primary
//! and diffuse rays with each, and prints one row per structure: build statistics, Mrays/s, speedup
//! over brute force, and the number of hits that differ from the default structure's (which makes the
//! benchmark a correctness check as well: any difference is an error, exit 3).
//!
//! Rays are generated once from the default structure (bvh-sah) and its hits ([`arbor::bench`]). Brute
//! force traces a deterministic sample of every ray set (every k-th ray), sized so that it takes
//! seconds, not hours; its rate is what the speedups divide by.

use std::path::{Path, PathBuf};

use arbor::accel::{AccelConfig, AccelKind, AccelStats, Hit};
use arbor::bench::{diffuse_rays, framing_camera, mesh_scene, mismatches, primary_rays, sample, sphere_mesh, trace};
use arbor::math::Ray;
use arbor::scene::{Scene, SceneDesc};
use serde_json::json;

use super::args::{specs, AccelList, BenchArgs};
use crate::Failure;

/// The structure every other one is compared with, and that generates the rays.
const REFERENCE: AccelKind = AccelKind::BvhSah;

/// Triangle tests brute force may spend per ray set (sets the default sample size).
const BRUTE_BUDGET: usize = 500_000_000;

/// One ray set as traced by the reference.
struct RaySet {
    name: &'static str,
    rays: Vec<Ray>,
    hits: Vec<Option<Hit>>,
    timed: bool,
}

/// What one structure measured on one ray set.
struct SetResult {
    mrays: f64,
    traced: usize,
    mismatches: usize,
}

/// Runs `arbor bench INPUT` without `--ray-dir`.
pub fn run(args: &BenchArgs) -> Result<(), Failure> {
    let all = || AccelList(AccelKind::ALL.to_vec());
    args.threads.apply()?;
    let specs = specs(&args.accel.clone().unwrap_or_else(all).0, &args.accel_params)?;
    let desc = load_input(&args.input, args.size)?;
    let limits = crate::render::limits(args.no_limits);
    arbor::scene::check_limits(&desc, None, &limits)?;
    let build = |spec: &AccelConfig| Scene::build_within(desc.clone(), spec, None, &limits.images);
    if desc.cameras.is_empty() {
        return Err(arbor::Error::Invalid(format!("{}: the scene has no camera", args.input)).into());
    }
    let reference = build(&AccelConfig::from(REFERENCE))?;
    let primary = primary_rays(&reference.cameras[0]);
    let (primary_hits, _) = trace(&reference.geometry, &primary);
    let diffuse = diffuse_rays(&reference, &primary, &primary_hits);
    let (diffuse_hits, _) = trace(&reference.geometry, &diffuse);
    let sets = [
        RaySet { name: "primary", rays: primary, hits: primary_hits, timed: args.rays.has("primary") },
        RaySet { name: "diffuse", rays: diffuse, hits: diffuse_hits, timed: args.rays.has("diffuse") },
    ];
    let prims = reference.geometry.counts.triangles + reference.geometry.counts.spheres;
    drop(reference);

    eprintln!("bench: tracing a sample with brute force");
    let brute_max = args.brute_rays.map_or((BRUTE_BUDGET / prims.max(1)).clamp(64, 4096), |n| n as usize);
    let brute_scene = build(&AccelConfig::Brute)?;
    let brute: Vec<SetResult> = sets.iter().map(|s| measure(&brute_scene, s, Some(brute_max), args.runs)).collect();
    let brute_stats = brute_scene.geometry.accel_stats();
    drop(brute_scene);

    let mut rows: Vec<(AccelStats, Vec<SetResult>)> = Vec::new();
    for spec in &specs {
        if spec.kind() == AccelKind::Brute {
            let again = sets.iter().map(|s| measure_again(&brute, s)).collect();
            rows.push((AccelStats { kind: spec.kind().name(), ..brute_stats.clone() }, again));
            continue;
        }
        // Progress on standard error: a slow structure should not look like a hang.
        eprintln!("bench: tracing with {}", spec.kind());
        let scene = build(spec)?;
        let results = sets.iter().map(|s| measure(&scene, s, None, args.runs)).collect();
        // Named by what was asked for: a structure may report another's name while it delegates.
        rows.push((AccelStats { kind: spec.kind().name(), ..scene.geometry.accel_stats() }, results));
    }
    let total_mismatch: usize = rows.iter().flat_map(|(_, r)| r).map(|r| r.mismatches).sum();
    if args.json {
        print_json(args, prims, &sets, &brute, &rows);
    } else {
        print_table(args, prims, &sets, &brute, &rows);
    }
    if total_mismatch > 0 {
        return Err(arbor::Error::Invalid(format!(
            "{total_mismatch} hits differ from {REFERENCE}'s (see the mismatch column)"
        ))
        .into());
    }
    Ok(())
}

/// The scene to benchmark: a scene file, a mesh file under a default camera, or a generated sphere.
fn load_input(input: &str, size: Option<(u32, u32)>) -> Result<SceneDesc, Failure> {
    let (w, h) = size.unwrap_or((1024, 1024));
    if let Some(n) = input.strip_prefix("sphere:") {
        let n: usize = n.trim().parse().ok().filter(|&n| (1..=50_000_000).contains(&n)).ok_or_else(|| {
            arbor::Error::Invalid(format!("'{input}': expected sphere:N with N from 1 to 50000000 triangles"))
        })?;
        let mesh = sphere_mesh(n);
        let camera = framing_camera(mesh.bounds(), w, h);
        return Ok(mesh_scene(mesh, Path::new(input), camera));
    }
    let path = PathBuf::from(input);
    let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
    if matches!(ext.as_deref(), Some("ply" | "obj" | "off")) {
        let mesh = arbor::mesh_io::load_mesh(&path)?;
        let camera = framing_camera(mesh.bounds(), w, h);
        return Ok(mesh_scene(mesh, &path, camera));
    }
    let mut desc = arbor::scene::load_desc(&path)?;
    if let (Some((w, h)), Some(cam)) = (size, desc.cameras.first_mut()) {
        (cam.width, cam.height) = (w, h);
    }
    Ok(desc)
}

/// Traces `set` (or a sample of at most `sample_max` of its rays) once to compare the hits, then `runs`
/// timed times when the set is timed (a brute-force sample: that one pass); the median rate.
fn measure(scene: &Scene, set: &RaySet, sample_max: Option<usize>, runs: u32) -> SetResult {
    let (rays, hits) = match sample_max {
        Some(max) => {
            let (rays, k) = sample(&set.rays, max);
            (rays, set.hits.iter().step_by(k).copied().collect())
        }
        None => (set.rays.clone(), set.hits.clone()),
    };
    // The first pass checks the hits and warms caches and the thread pool; timed passes follow. Brute
    // force's sample is sized for one pass within its budget: that pass is its timing.
    let (got, first) = trace(&scene.geometry, &rays);
    let mismatch = mismatches(&got, &hits);
    let mut times = if sample_max.is_some() && set.timed { vec![first.as_secs_f64()] } else { Vec::new() };
    for _ in 0..if set.timed && sample_max.is_none() { runs } else { 0 } {
        times.push(trace(&scene.geometry, &rays).1.as_secs_f64());
    }
    if times.is_empty() {
        return SetResult { mrays: f64::NAN, traced: rays.len(), mismatches: mismatch };
    }
    times.sort_by(f64::total_cmp);
    let median = times[times.len() / 2].max(1e-9);
    let mrays = rays.len() as f64 / median / 1e6;
    SetResult { mrays, traced: rays.len(), mismatches: mismatch }
}

fn measure_again(brute: &[SetResult], set: &RaySet) -> SetResult {
    let r = &brute[if set.name == "primary" { 0 } else { 1 }];
    SetResult { mrays: r.mrays, traced: r.traced, mismatches: r.mismatches }
}

fn fmt_rate(x: f64) -> String {
    if x.is_finite() && x < 0.01 {
        // Brute force on big meshes: keep significant digits.
        format!("{x:.2e}")
    } else if x.is_finite() {
        format!("{x:.3}")
    } else {
        "-".into()
    }
}

fn print_table(
    args: &BenchArgs,
    prims: usize,
    sets: &[RaySet],
    brute: &[SetResult],
    rows: &[(AccelStats, Vec<SetResult>)],
) {
    say!("input      {} ({prims} primitives), {} threads", args.input, rayon::current_num_threads());
    say!(
        "kernel     {} (the BVH's node test, detected at run time; processor: {})",
        arbor::accel::bvh::query_kernel(),
        super::ray_dir::cpu_features()
    );
    for (set, b) in sets.iter().zip(brute) {
        say!(
            "rays       {}: {} ({} hit by {REFERENCE}); brute force traces a sample of {}{}",
            set.name,
            set.rays.len(),
            set.hits.iter().flatten().count(),
            b.traced,
            if set.timed { "" } else { " (not timed)" }
        );
    }
    let header = [
        "structure",
        "build ms",
        "KiB",
        "nodes",
        "leaves",
        "depth",
        "mean d",
        "prims/leaf",
        "refs/prim",
        "SAH",
        "primary Mr/s",
        "diffuse Mr/s",
        "x brute P",
        "x brute D",
        "mismatch",
    ];
    let mut lines = vec![header.iter().map(|s| s.to_string()).collect::<Vec<_>>()];
    for (s, r) in rows {
        let speedup = |i: usize| fmt_ratio(r[i].mrays / brute[i].mrays);
        lines.push(vec![
            s.kind.to_string(),
            format!("{:.1}", s.build_time.as_secs_f64() * 1e3),
            format!("{:.1}", s.bytes as f64 / 1024.0),
            s.nodes.to_string(),
            s.leaves.to_string(),
            s.max_depth.to_string(),
            format!("{:.1}", s.mean_depth),
            format!("{:.2}", s.mean_leaf_prims),
            format!("{:.2}", s.refs_per_prim),
            format!("{:.1}", s.sah_cost),
            fmt_rate(r[0].mrays),
            fmt_rate(r[1].mrays),
            speedup(0),
            speedup(1),
            (r[0].mismatches + r[1].mismatches).to_string(),
        ]);
    }
    let widths: Vec<usize> = (0..header.len()).map(|c| lines.iter().map(|l| l[c].len()).max().unwrap_or(0)).collect();
    for l in &lines {
        let cells: Vec<String> = l
            .iter()
            .enumerate()
            .map(|(c, v)| if c == 0 { format!("{v:<w$}", w = widths[c]) } else { format!("{v:>w$}", w = widths[c]) })
            .collect();
        say!("{}", cells.join("  "));
    }
}

fn fmt_ratio(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.1}")
    } else {
        "-".into()
    }
}

fn print_json(
    args: &BenchArgs,
    prims: usize,
    sets: &[RaySet],
    brute: &[SetResult],
    rows: &[(AccelStats, Vec<SetResult>)],
) {
    let num = |x: f64| if x.is_finite() { json!(x) } else { json!(null) };
    let structures: Vec<_> = rows
        .iter()
        .map(|(s, r)| {
            let per_set = |i: usize| {
                json!({
                    "mrays": num(r[i].mrays),
                    "speedup": num(r[i].mrays / brute[i].mrays),
                    "rays_traced": r[i].traced,
                    "mismatches": r[i].mismatches,
                })
            };
            json!({
                "kind": s.kind,
                "build_ms": s.build_time.as_secs_f64() * 1e3,
                "bytes": s.bytes,
                "nodes": s.nodes,
                "leaves": s.leaves,
                "max_depth": s.max_depth,
                "mean_depth": num(s.mean_depth),
                "mean_leaf_prims": num(s.mean_leaf_prims),
                "refs_per_prim": num(s.refs_per_prim),
                "sah_cost": num(s.sah_cost),
                "primary": per_set(0),
                "diffuse": per_set(1),
                "mismatches": r[0].mismatches + r[1].mismatches,
            })
        })
        .collect();
    let rays: serde_json::Map<String, serde_json::Value> = sets
        .iter()
        .zip(brute)
        .map(|(s, b)| {
            let v = json!({"rays": s.rays.len(), "timed": s.timed, "brute_sample": b.traced});
            (s.name.to_string(), v)
        })
        .collect();
    let doc = json!({
        "input": args.input,
        "primitives": prims,
        "threads": rayon::current_num_threads(),
        "kernel": arbor::accel::bvh::query_kernel(),
        "reference": REFERENCE.name(),
        "runs": args.runs,
        "rays": rays,
        "structures": structures,
    });
    say!("{}", serde_json::to_string_pretty(&doc).unwrap_or_default());
}
