//! The batch queries behind the Python methods, on plain Rust data (array views in, vectors out), run
//! on a rayon pool of the threads asked for, in chunks of [`CHUNK`] rays: each chunk is one
//! `intersect_many_coherent`/`occluded_many` call, so the BVH's interleaved two-ray traversal serves
//! Python callers as it serves the renderer's camera rays, and runs of rays in a coherent order (a
//! scanner's rows, a camera's pixels: arrays are often made so) go as packets (igea's parallel rays
//! 1.13x, the icosphere's sparser ones 0.96x: docs/performance.md); closest points likewise, in `f64` from the points as given. No query
//! here takes the GIL.
//!
//! Costs outside the traversal, kept small because a closest-hit query of a coherent ray costs only
//! about a thousand instructions: each chunk's rays are read one argument at a time into buffers a
//! task reuses ([`Chunk`]); the closest-hit outputs are written once each, into uninitialised room
//! (no zeroing pass on the calling thread), and only those asked for ([`Fields`]): a normal or a
//! point reads the triangle's corners from the mesh, a cache miss per hit on a large mesh, so the
//! corners of a chunk's hits are gathered in a loop of their own that keeps many misses in flight.
//!
//! `t_min`: a ray with `t_min > 0` is queried from `origin + t_min * direction` (rounded to `f32`) over
//! `(0, t_max - t_min)`, and its `t` reported from the given origin. Every query (closest, any, all,
//! counts) uses that same ray, so their answers agree with each other; a negative `t_min` is 0 (rays
//! are half-lines), and a NaN anywhere in a ray (origin, direction, `t_min`, `t_max`) makes it a miss,
//! as do a zero direction and `t_max <= t_min`.

use std::mem::MaybeUninit;
use std::sync::{Arc, Mutex};

use arbor::accel::{ClosestPointUnsupported, Hit, Nearest, Structure};
use arbor::math::{Ray, Vec3};
use rayon::prelude::*;

use crate::arrays::{PerRay, Rows};
use crate::crossings::{contains, crossings, Collector};

/// Rays per task and per batch call: enough for the BVH's two-ray interleaving and to amortise a
/// task, few enough that 1M rays spread over every core.
pub const CHUNK: usize = 256;

/// Rays as given: origins, directions and their interval.
#[derive(Clone, Copy)]
pub struct RaySet<'a> {
    /// Origins, `(N, 3)`.
    pub origins: Rows<'a>,
    /// Directions, `(N, 3)`, any length: `t` is in units of it.
    pub dirs: Rows<'a>,
    /// Where each ray starts counting hits.
    pub t_min: PerRay<'a>,
    /// Where each ray stops.
    pub t_max: PerRay<'a>,
}

impl RaySet<'_> {
    /// How many rays.
    pub fn len(&self) -> usize {
        self.origins.len()
    }

    /// Ray `i` as queried (see the module documentation): the ray, its `t_max` from its own origin,
    /// and the `t` of that origin along the given ray.
    #[inline]
    pub fn ray(&self, i: usize) -> (Ray, f32, f32) {
        as_queried(self.origins.get(i), self.dirs.get(i), self.t_min.get(i), self.t_max.get(i))
    }

    /// Rays `base..base + k` as queried into `chunk` (`k <= CHUNK`): each argument is read in a pass
    /// of its own, its dtype and layout matched once per chunk rather than once per value.
    fn read(&self, base: usize, k: usize, chunk: &mut Chunk) {
        let Chunk { o, d, rays, t_max, shift, .. } = chunk;
        self.origins.read(base, &mut o[..k]);
        self.dirs.read(base, &mut d[..k]);
        self.t_min.read(base, &mut shift[..k]);
        self.t_max.read(base, &mut t_max[..k]);
        for j in 0..k {
            (rays[j], t_max[j], shift[j]) = as_queried(o[j], d[j], shift[j], t_max[j]);
        }
    }
}

/// The ray from `o` along `d` over `(t0, t1)` as queried (see the module documentation): the ray, its
/// `t_max` from its own origin, and the `t` of that origin along the given ray.
// Always inlined: called per ray, its returned tuple would otherwise go through the stack, whose
// narrow stores and wide reloads stall (seen in `perf annotate` of `RaySet::read`).
#[inline(always)]
fn as_queried(o: Vec3, d: Vec3, t0: f32, t1: f32) -> (Ray, f32, f32) {
    if t0.is_nan() {
        return (Ray::new(o, d), f32::NAN, 0.0);
    }
    if t0 > 0.0 {
        (Ray::new(o + t0 * d, d), t1 - t0, t0)
    } else {
        (Ray::new(o, d), t1, 0.0)
    }
}

/// One chunk's rays as queried and their hits (the first `k` entries), reused from chunk to chunk by
/// each task.
struct Chunk {
    o: Vec<Vec3>,
    d: Vec<Vec3>,
    rays: Vec<Ray>,
    t_max: Vec<f32>,
    shift: Vec<f32>,
    hits: Vec<Option<Hit>>,
    corners: Vec<[Vec3; 3]>,
}

impl Chunk {
    fn new() -> Self {
        Chunk {
            o: vec![Vec3::ZERO; CHUNK],
            d: vec![Vec3::ZERO; CHUNK],
            rays: vec![Ray::new(Vec3::ZERO, Vec3::Z); CHUNK],
            t_max: vec![0.0; CHUNK],
            shift: vec![0.0; CHUNK],
            hits: vec![None; CHUNK],
            corners: vec![[Vec3::ZERO; 3]; CHUNK],
        }
    }
}

/// Runs `f` on a pool of `threads` threads (all cores for `None`): the global pool, or one kept for
/// that count.
pub fn in_pool<R: Send>(threads: Option<usize>, f: impl FnOnce() -> R + Send) -> R {
    static POOLS: Mutex<Vec<(usize, Arc<rayon::ThreadPool>)>> = Mutex::new(Vec::new());
    let Some(n) = threads else { return f() };
    let pool = {
        let mut pools = POOLS.lock().unwrap_or_else(|e| e.into_inner());
        match pools.iter().find(|(k, _)| *k == n) {
            Some((_, p)) => Arc::clone(p),
            None => {
                let p = rayon::ThreadPoolBuilder::new().num_threads(n).build();
                // A pool that cannot start its threads: run on the global one rather than fail.
                let Ok(p) = p else { return f() };
                let p = Arc::new(p);
                pools.push((n, Arc::clone(&p)));
                p
            }
        }
    };
    pool.install(f)
}

/// The outputs of a closest-hit query a caller asks for; the others are not computed (a normal or a
/// point reads the triangle's corners from the mesh, a cache miss per hit).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fields {
    /// `t`.
    pub t: bool,
    /// `triangle`.
    pub triangle: bool,
    /// `u` and `v`.
    pub uv: bool,
    /// `normal`.
    pub normal: bool,
    /// `point`.
    pub point: bool,
}

/// Closest hits, one row per ray; misses have `t = inf`, triangle -1 and zeros elsewhere. A field not
/// asked for is empty.
pub struct Closest {
    /// Ray parameter of the hit, in units of the direction's length, from the given origin.
    pub t: Vec<f32>,
    /// Triangle index.
    pub triangle: Vec<i64>,
    /// Barycentric weight of the triangle's vertex 1.
    pub u: Vec<f32>,
    /// Barycentric weight of its vertex 2.
    pub v: Vec<f32>,
    /// Unit geometric normal (counter-clockwise side), `3N` values.
    pub normal: Vec<f32>,
    /// Hit point from the barycentrics, on the triangle, `3N` values.
    pub point: Vec<f32>,
}

/// The unit normal of the triangle of corners `[a, b, c]` (counter-clockwise side).
pub fn unit_normal(corners: [Vec3; 3]) -> [f32; 3] {
    let [a, b, c] = corners.map(|p| p.as_dvec3());
    (b - a).cross(c - a).normalize_or_zero().as_vec3().to_array()
}

/// The point of weights `(u, v)` on the triangle of corners `[a, b, c]` (in `f64`, rounded once).
pub fn surface_point(corners: [Vec3; 3], u: f32, v: f32) -> [f32; 3] {
    let [a, b, c] = corners.map(|p| p.as_dvec3());
    (a + (b - a) * u as f64 + (c - a) * v as f64).as_vec3().to_array()
}

/// The first `len` values of `v`'s room (`len` is 0 or what it was made with) in pieces of
/// `width * CHUNK` values, one per chunk (none for a field not asked for).
fn pieces<T>(v: &mut Vec<T>, len: usize, width: usize) -> impl Iterator<Item = &mut [MaybeUninit<T>]> {
    v.spare_capacity_mut()[..len].chunks_mut(width * CHUNK)
}

/// One chunk's rows of every output, to be written.
struct OutRows<'a> {
    t: &'a mut [MaybeUninit<f32>],
    triangle: &'a mut [MaybeUninit<i64>],
    u: &'a mut [MaybeUninit<f32>],
    v: &'a mut [MaybeUninit<f32>],
    normal: &'a mut [MaybeUninit<f32>],
    point: &'a mut [MaybeUninit<f32>],
}

/// Writes `x` into the three values of `row`.
#[inline]
fn write3(row: &mut [MaybeUninit<f32>], x: [f32; 3]) {
    for (r, x) in row.iter_mut().zip(x) {
        r.write(x);
    }
}

/// The closest hit of every ray, with the outputs of `fields`.
pub fn closest(s: &Structure, rays: RaySet<'_>, fields: Fields) -> Closest {
    let n = rays.len();
    // Room for each field asked for, uninitialised: the loop below writes every value (no pass over
    // the memory before the query, and each task touches the pages of its own rows).
    let len = |on: bool, width: usize| if on { width * n } else { 0 };
    let mut out = Closest {
        t: Vec::with_capacity(len(fields.t, 1)),
        triangle: Vec::with_capacity(len(fields.triangle, 1)),
        u: Vec::with_capacity(len(fields.uv, 1)),
        v: Vec::with_capacity(len(fields.uv, 1)),
        normal: Vec::with_capacity(len(fields.normal, 3)),
        point: Vec::with_capacity(len(fields.point, 3)),
    };
    let mesh = s.primitives().as_ref();
    let chunks = n.div_ceil(CHUNK);
    // The pieces borrow `out` until every row is written.
    {
        let mut t = pieces(&mut out.t, len(fields.t, 1), 1);
        let mut triangle = pieces(&mut out.triangle, len(fields.triangle, 1), 1);
        let mut u = pieces(&mut out.u, len(fields.uv, 1), 1);
        let mut v = pieces(&mut out.v, len(fields.uv, 1), 1);
        let mut normal = pieces(&mut out.normal, len(fields.normal, 3), 3);
        let mut point = pieces(&mut out.point, len(fields.point, 3), 3);
        let rows: Vec<OutRows<'_>> = (0..chunks)
            .map(|_| OutRows {
                t: t.next().unwrap_or_default(),
                triangle: triangle.next().unwrap_or_default(),
                u: u.next().unwrap_or_default(),
                v: v.next().unwrap_or_default(),
                normal: normal.next().unwrap_or_default(),
                point: point.next().unwrap_or_default(),
            })
            .collect();
        rows.into_par_iter().enumerate().for_each_init(Chunk::new, |chunk, (c, o)| {
            let base = c * CHUNK;
            let k = CHUNK.min(n - base);
            rays.read(base, k, chunk);
            s.intersect_many_coherent(&chunk.rays[..k], &chunk.t_max[..k], &mut chunk.hits[..k]);
            if fields.normal || fields.point {
                // The corners of every triangle hit, gathered in a loop of loads alone: on a large mesh
                // they miss the cache, and this keeps many misses in flight where the arithmetic on
                // each would keep a few.
                for (c, h) in chunk.corners.iter_mut().zip(&chunk.hits[..k]) {
                    *c = h.map_or([Vec3::ZERO; 3], |h| mesh.triangle(h.prim as usize));
                }
            }
            // Every row of every field asked for is written, hit or miss.
            for (j, h) in chunk.hits[..k].iter().enumerate() {
                let (ht, tri, hu, hv) = match h {
                    Some(h) => (h.t + chunk.shift[j], h.prim as i64, h.u, h.v),
                    None => (f32::INFINITY, -1, 0.0, 0.0),
                };
                if fields.t {
                    o.t[j].write(ht);
                }
                if fields.triangle {
                    o.triangle[j].write(tri);
                }
                if fields.uv {
                    o.u[j].write(hu);
                    o.v[j].write(hv);
                }
                if fields.normal {
                    write3(&mut o.normal[3 * j..3 * j + 3], h.map_or([0.0; 3], |_| unit_normal(chunk.corners[j])));
                }
                if fields.point {
                    let p = h.map_or([0.0; 3], |h| surface_point(chunk.corners[j], h.u, h.v));
                    write3(&mut o.point[3 * j..3 * j + 3], p);
                }
            }
        });
    }
    // SAFETY: `Vec::set_len` needs the first `len` values initialised. The chunks cover rays `0..n`,
    // and the loop above wrote every row of each of them, hit or miss, in every field asked for
    // (whose `len` is its width times `n`); a field not asked for keeps length 0.
    unsafe {
        out.t.set_len(len(fields.t, 1));
        out.triangle.set_len(len(fields.triangle, 1));
        out.u.set_len(len(fields.uv, 1));
        out.v.set_len(len(fields.uv, 1));
        out.normal.set_len(len(fields.normal, 3));
        out.point.set_len(len(fields.point, 3));
    }
    out
}

/// Whether each ray hits anything in its interval (the structure's any-hit query: it stops at the
/// first hit it finds).
pub fn occluded(s: &Structure, rays: RaySet<'_>) -> Vec<bool> {
    let n = rays.len();
    let mut out = vec![false; n];
    out.par_chunks_mut(CHUNK).enumerate().for_each_init(Chunk::new, |chunk, (c, o)| {
        rays.read(c * CHUNK, o.len(), chunk);
        s.occluded_many(&chunk.rays[..o.len()], &chunk.t_max[..o.len()], o);
    });
    out
}

/// Every crossing of every ray, flattened in ray order then `t` order, at most `max_hits` per ray.
pub struct AllHits {
    /// The ray of each crossing.
    pub ray: Vec<i64>,
    /// Its triangle.
    pub triangle: Vec<i64>,
    /// Its `t`, from the given origin.
    pub t: Vec<f32>,
    /// Barycentric weight of vertex 1.
    pub u: Vec<f32>,
    /// Barycentric weight of vertex 2.
    pub v: Vec<f32>,
    /// The point on the triangle, `3K` values.
    pub point: Vec<f32>,
}

/// The crossings of every ray ([`crate::crossings`]), at most `max_hits` per ray (the closest ones).
pub fn all_hits(s: &Structure<Collector>, rays: RaySet<'_>, max_hits: usize) -> AllHits {
    let mesh = s.primitives().mesh.as_ref();
    let parts: Vec<AllHits> = (0..rays.len().div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            let mut part = AllHits { ray: vec![], triangle: vec![], t: vec![], u: vec![], v: vec![], point: vec![] };
            for i in c * CHUNK..((c + 1) * CHUNK).min(rays.len()) {
                let (r, t1, s0) = rays.ray(i);
                for h in crossings(s, &r, t1).into_iter().take(max_hits) {
                    part.ray.push(i as i64);
                    part.triangle.push(h.prim as i64);
                    part.t.push(h.t + s0);
                    part.u.push(h.u);
                    part.v.push(h.v);
                    part.point.extend(surface_point(mesh.triangle(h.prim as usize), h.u, h.v));
                }
            }
            part
        })
        .collect();
    let mut all = AllHits { ray: vec![], triangle: vec![], t: vec![], u: vec![], v: vec![], point: vec![] };
    for p in parts {
        all.ray.extend(p.ray);
        all.triangle.extend(p.triangle);
        all.t.extend(p.t);
        all.u.extend(p.u);
        all.v.extend(p.v);
        all.point.extend(p.point);
    }
    all
}

/// The number of crossings of every ray (no cap).
pub fn count_crossings(s: &Structure<Collector>, rays: RaySet<'_>) -> Vec<i64> {
    (0..rays.len())
        .into_par_iter()
        .with_min_len(CHUNK)
        .map(|i| {
            let (r, t1, _) = rays.ray(i);
            crossings(s, &r, t1).len() as i64
        })
        .collect()
}

/// Whether each point is inside the closed mesh ([`crate::crossings::contains`]).
pub fn contains_points(s: &Structure<Collector>, points: Rows<'_>) -> Vec<bool> {
    (0..points.len()).into_par_iter().with_min_len(64).map(|i| contains(s, points.get(i))).collect()
}

/// Closest points, one row per point; a point with nothing within the bound has distance `inf`,
/// triangle -1 and NaN elsewhere.
pub struct ClosestPoints {
    /// The nearest point on the mesh, `3N` values.
    pub point: Vec<f64>,
    /// Its distance.
    pub distance: Vec<f64>,
    /// Its triangle.
    pub triangle: Vec<i64>,
    /// Barycentric weight of the triangle's vertex 1.
    pub u: Vec<f64>,
    /// Barycentric weight of its vertex 2.
    pub v: Vec<f64>,
}

/// The closest point on the mesh of every point, within `max_distance` (`Structure::closest_point`:
/// ties to the lowest triangle index), in chunks of [`CHUNK`] points.
pub fn closest_points(
    s: &Structure,
    points: Rows<'_>,
    max_distance: f64,
) -> Result<ClosestPoints, ClosestPointUnsupported> {
    s.check_closest_point()?;
    let n = points.len();
    let mut out = ClosestPoints {
        point: vec![f64::NAN; 3 * n],
        distance: vec![f64::INFINITY; n],
        triangle: vec![-1; n],
        u: vec![f64::NAN; n],
        v: vec![f64::NAN; n],
    };
    out.distance
        .par_chunks_mut(CHUNK)
        .zip(out.triangle.par_chunks_mut(CHUNK))
        .zip(out.u.par_chunks_mut(CHUNK))
        .zip(out.v.par_chunks_mut(CHUNK))
        .zip(out.point.par_chunks_mut(3 * CHUNK))
        .enumerate()
        .for_each(|(c, ((((d, tri), u), v), pt))| {
            let batch: Vec<_> = (c * CHUNK..c * CHUNK + d.len()).map(|i| points.get_f64(i)).collect();
            let mut found: Vec<Option<Nearest>> = vec![None; batch.len()];
            // Answers: checked above.
            let _ = s.closest_points_many(&batch, max_distance, &mut found);
            for (j, f) in found.iter().enumerate() {
                let Some(f) = f else { continue };
                d[j] = f.distance();
                tri[j] = f.prim as i64;
                (u[j], v[j]) = (f.u, f.v);
                pt[3 * j..3 * j + 3].copy_from_slice(&f.point.to_array());
            }
        });
    Ok(out)
}
