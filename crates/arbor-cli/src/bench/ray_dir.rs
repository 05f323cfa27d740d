//! `arbor bench MESH --ray-dir DIR`: traces the rays the peers' harness dumped (`peerbench --dump-rays
//! DIR`) with Arbor's structures over the same mesh, and prints one line per (structure, ray set) in
//! peerbench's own format, so that one script can put Arbor and the peers side by side on identical rays.
//!
//! Measured as peerbench measures its peers: one untimed warm-up build of a small mesh, then the
//! median of `--runs` builds of the mesh (wall time from the loaded mesh to a traceable structure);
//! each ray set traced at least 3 times and for at least 0.3 s (stopping after 2.5 s), median rate.
//! One thread traces on the calling thread; more threads trace 1024-ray chunks on the rayon pool.
//!
//! Every structure is traced twice: one query per ray (`peer=arbor-KIND`, as peerbench calls Embree's
//! `rtcIntersect1`), and whole batches through [`Accel::intersect_many`] (`peer=arbor-KIND-batch`, the
//! BVH interleaving two rays; the renderer traces its camera rays so).
//! With `--query any`, the same two forms of the any-hit query (`occluded`, `occluded_many`) run
//! instead, as `peer=arbor-KIND-any` and `-any-batch`; their `mismatch` counts rays whose answer
//! differs from whether the reference peer hit anything.
//! `mismatch` is the share of rays whose hit disagrees with the reference peer's (hit or miss, or `t`
//! off by more than 1e-4 relative, see [`disagrees`]).
//!
//! Each line also gives `cpu_build_ms` and `cpu_mrays`, the same medians in process CPU time
//! (`getrusage`): on a machine shared with other jobs, wall time counts the time the scheduler gave
//! to others, CPU time does not. Ratios to the peers use wall time, as the peers report only that.

use std::path::Path;
use std::time::{Duration, Instant};

use arbor::accel::{Accel, AccelKind, Hit};
use arbor::bench::ray_files::{disagrees, load_ray_set, RaySetFile};
use arbor::bench::sphere_mesh;
use arbor::geometry::TriangleMesh;
use arbor::math::Ray;
use rayon::prelude::*;

use super::args::{specs, BenchArgs, Query};
use crate::Failure;

/// Rays per parallel work item (peerbench's chunk size).
const CHUNK: usize = 1024;
/// Every set is traced for at least this long in total...
const MIN_TIME: Duration = Duration::from_millis(300);
/// ...and at least this many times, but no more passes start after [`MAX_TIME`].
const MIN_RUNS: usize = 3;
const MAX_TIME: Duration = Duration::from_millis(2500);

/// Runs `arbor bench MESH --ray-dir DIR`.
pub fn run(args: &BenchArgs, dir: &Path) -> Result<(), Failure> {
    // `all` leaves out brute force here: it would take hours on a million rays.
    let kinds = match &args.accel {
        None => vec![AccelKind::BvhSah],
        Some(a) if a.0 == AccelKind::ALL => a.0.iter().copied().filter(|&k| k != AccelKind::Brute).collect(),
        Some(a) => a.0.clone(),
    };
    let kinds = specs(&kinds, &args.accel_params)?;
    args.threads.apply()?;
    let threads = args.threads.count().max(1);
    let path = Path::new(&args.input);
    let start = Instant::now();
    let mesh = arbor::mesh_io::load_mesh(path)?;
    let load = start.elapsed();
    let bytes = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    say!(
        "# mesh={} tris={} load_ms={:.1} ({:.0} MB/s)",
        args.input,
        mesh.len(),
        load.as_secs_f64() * 1e3,
        bytes as f64 / load.as_secs_f64().max(1e-9) / 1e6
    );
    let kernel = arbor::accel::bvh::query_kernel();
    say!("# kernel={kernel} (the BVH's node test, detected at run time; processor: {})", cpu_features());
    let sets: Vec<RaySetFile> = ["primary", "diffuse"]
        .into_iter()
        .filter(|name| args.rays.has(name))
        .map(|name| load_ray_set(dir, name, mesh.len()))
        .collect::<Result<_, _>>()?;
    let batches: Vec<Batch> = sets
        .iter()
        .map(|s| Batch {
            rays: s.rays.iter().map(|r| r.ray).collect(),
            t_max: s.rays.iter().map(|r| r.t_max).collect(),
        })
        .collect();
    let warm_up = sphere_mesh(2000);
    for spec in &kinds {
        drop(spec.build_accel(&warm_up).map_err(|e| Failure::Usage(e.to_string()))?);
        let mut builds = Vec::new();
        let mut cpu_builds = Vec::new();
        let mut accel = None;
        for _ in 0..args.runs {
            drop(accel.take());
            let (start, cpu) = (Instant::now(), cpu_time());
            let built = spec.build_accel(&mesh).map_err(|e| Failure::Usage(e.to_string()))?;
            builds.push(start.elapsed().as_secs_f64() * 1e3);
            cpu_builds.push((cpu_time() - cpu).as_secs_f64() * 1e3);
            accel = Some(built);
        }
        let Some(accel) = accel else { continue };
        let build_ms = median(&mut builds);
        let cpu_build_ms = median(&mut cpu_builds);
        let list: Vec<String> = builds.iter().map(|b| format!("{b:.1}")).collect();
        say!("# peer=arbor-{} built in {} ms", spec.kind(), list.join(", "));
        for (set, batch) in sets.iter().zip(&batches) {
            let modes = match args.query {
                Query::Closest => [Mode::Single, Mode::Batch],
                Query::Any => [Mode::AnySingle, Mode::AnyBatch],
            };
            for mode in modes {
                let r = measure(accel.as_ref(), &mesh, set, batch, threads, mode);
                say!(
                    "peer=arbor-{}{} set={} threads={threads} build_ms={build_ms:.2} mrays={:.3} hits={} mesh={} \
                     tris={} rays={} runs={} vs=reference mismatch={:.6} cpu_build_ms={cpu_build_ms:.2} \
                     cpu_mrays={:.3} kernel={kernel}",
                    spec.kind(),
                    mode.suffix(),
                    set.name,
                    r.mrays,
                    r.hits,
                    path.file_name().map_or_else(|| args.input.clone(), |f| f.to_string_lossy().into_owned()),
                    mesh.len(),
                    set.rays.len(),
                    r.runs,
                    r.mismatch,
                    r.cpu_mrays
                );
            }
        }
    }
    Ok(())
}

struct Measured {
    mrays: f64,
    cpu_mrays: f64,
    hits: usize,
    runs: usize,
    mismatch: f64,
}

/// How the rays are handed to the structure.
#[derive(Clone, Copy)]
enum Mode {
    /// One [`Accel::intersect`] per ray.
    Single,
    /// [`Accel::intersect_many`] over the whole set (one thread) or each chunk.
    Batch,
    /// One [`Accel::occluded`] per ray.
    AnySingle,
    /// [`Accel::occluded_many`] over the whole set (one thread) or each chunk.
    AnyBatch,
}

impl Mode {
    fn suffix(self) -> &'static str {
        match self {
            Mode::Single => "",
            Mode::Batch => "-batch",
            Mode::AnySingle => "-any",
            Mode::AnyBatch => "-any-batch",
        }
    }
}

/// A ray set as the batch query takes it, built before timing.
struct Batch {
    rays: Vec<Ray>,
    t_max: Vec<f32>,
}

fn measure(
    accel: &dyn Accel<TriangleMesh>,
    mesh: &TriangleMesh,
    set: &RaySetFile,
    batch: &Batch,
    threads: usize,
    mode: Mode,
) -> Measured {
    let mut hits = vec![None; set.rays.len()];
    let mut blocked = vec![false; set.rays.len()];
    let mut times = Vec::new();
    let mut cpu_times = Vec::new();
    let mut total = Duration::ZERO;
    while times.len() < MIN_RUNS || total < MIN_TIME {
        let (start, cpu) = (Instant::now(), cpu_time());
        trace_all(accel, mesh, batch, threads, mode, &mut hits, &mut blocked);
        let dt = start.elapsed();
        total += dt;
        times.push(dt.as_secs_f64());
        cpu_times.push((cpu_time() - cpu).as_secs_f64());
        if total > MAX_TIME {
            break;
        }
    }
    let secs = median(&mut times).max(1e-9);
    let (wrong, hit) = match mode {
        Mode::Single | Mode::Batch => (
            hits.iter().zip(&set.hits).filter(|(h, r)| disagrees(h.map(|h| h.t), r)).count(),
            hits.iter().flatten().count(),
        ),
        Mode::AnySingle | Mode::AnyBatch => (
            blocked.iter().zip(&set.hits).filter(|(&b, r)| b != r.is_hit()).count(),
            blocked.iter().filter(|&&b| b).count(),
        ),
    };
    Measured {
        mrays: set.rays.len() as f64 / secs / 1e6,
        cpu_mrays: set.rays.len() as f64 / median(&mut cpu_times).max(1e-9) / 1e6,
        hits: hit,
        runs: times.len(),
        mismatch: wrong as f64 / set.rays.len().max(1) as f64,
    }
}

/// The batch's closest hits into `out` or any-hit answers into `blocked`, as `mode` asks: on this
/// thread for one thread, else in chunks on rayon.
fn trace_all(
    accel: &dyn Accel<TriangleMesh>,
    mesh: &TriangleMesh,
    batch: &Batch,
    threads: usize,
    mode: Mode,
    out: &mut [Option<Hit>],
    blocked: &mut [bool],
) {
    let trace = |rays: &[Ray], t_max: &[f32], out: &mut [Option<Hit>], blocked: &mut [bool]| match mode {
        Mode::Single => {
            for ((o, r), &t) in out.iter_mut().zip(rays).zip(t_max) {
                *o = accel.intersect(mesh, r, t);
            }
        }
        Mode::Batch => accel.intersect_many(mesh, rays, t_max, out),
        Mode::AnySingle => {
            for ((b, r), &t) in blocked.iter_mut().zip(rays).zip(t_max) {
                *b = accel.occluded(mesh, r, t);
            }
        }
        Mode::AnyBatch => accel.occluded_many(mesh, rays, t_max, blocked),
    };
    if threads == 1 {
        trace(&batch.rays, &batch.t_max, out, blocked);
    } else {
        out.par_chunks_mut(CHUNK)
            .zip(blocked.par_chunks_mut(CHUNK))
            .zip(batch.rays.par_chunks(CHUNK))
            .zip(batch.t_max.par_chunks(CHUNK))
            .for_each(|(((o, b), r), t)| trace(r, t, o, b));
    }
}

/// The processor's SIMD extensions that a wider kernel could use, e.g. `avx2=yes avx512f=no`.
pub(super) fn cpu_features() -> String {
    #[cfg(target_arch = "x86_64")]
    {
        let yes = |b: bool| if b { "yes" } else { "no" };
        format!(
            "avx2={} fma={} avx512f={} avx512vl={}",
            yes(std::is_x86_feature_detected!("avx2")),
            yes(std::is_x86_feature_detected!("fma")),
            yes(std::is_x86_feature_detected!("avx512f")),
            yes(std::is_x86_feature_detected!("avx512vl"))
        )
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        std::env::consts::ARCH.to_string()
    }
}

fn median(xs: &mut [f64]) -> f64 {
    xs.sort_by(f64::total_cmp);
    xs.get(xs.len() / 2).copied().unwrap_or(f64::NAN)
}

/// CPU time of the whole process so far (user and system, every thread).
fn cpu_time() -> Duration {
    // SAFETY: `rusage` is plain old data (integers and `timeval`s), for which all zero bytes are valid.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: `getrusage` only writes the struct it is given, which lives for the whole call.
    if unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) } != 0 {
        return Duration::ZERO;
    }
    let tv = |t: libc::timeval| Duration::new(t.tv_sec.max(0) as u64, (t.tv_usec.max(0) as u32) * 1000);
    tv(u.ru_utime) + tv(u.ru_stime)
}
