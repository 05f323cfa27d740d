//! The batch queries behind the Python methods, on plain Rust data (array views in, vectors out), run
//! on a rayon pool of the threads asked for, in chunks of [`CHUNK`] rays: each chunk is one
//! `intersect_many`/`occluded_many` call, so the BVH's interleaved two-ray traversal serves Python
//! callers as it serves the renderer's camera rays; closest points likewise, in `f64` from the points
//! as given. No query here takes the GIL.
//!
//! `t_min`: a ray with `t_min > 0` is queried from `origin + t_min * direction` (rounded to `f32`) over
//! `(0, t_max - t_min)`, and its `t` reported from the given origin. Every query (closest, any, all,
//! counts) uses that same ray, so their answers agree with each other; a negative `t_min` is 0 (rays
//! are half-lines), and a NaN anywhere in a ray (origin, direction, `t_min`, `t_max`) makes it a miss,
//! as do a zero direction and `t_max <= t_min`.

use std::sync::{Arc, Mutex};

use arbor::accel::{ClosestPointUnsupported, Hit, Nearest, Structure};
use arbor::geometry::TriangleMesh;
use arbor::math::Ray;
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
        let (o, d) = (self.origins.get(i), self.dirs.get(i));
        let (t0, t1) = (self.t_min.get(i), self.t_max.get(i));
        if t0.is_nan() {
            return (Ray::new(o, d), f32::NAN, 0.0);
        }
        if t0 > 0.0 {
            (Ray::new(o + t0 * d, d), t1 - t0, t0)
        } else {
            (Ray::new(o, d), t1, 0.0)
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

/// Closest hits, one row per ray; misses have `t = inf`, triangle -1 and zeros elsewhere.
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

/// The unit normal of triangle `prim` and the point of weights `(u, v)` on it (in `f64`, rounded once).
pub fn surface(mesh: &TriangleMesh, prim: u32, u: f32, v: f32) -> ([f32; 3], [f32; 3]) {
    let [a, b, c] = mesh.triangle(prim as usize).map(|p| p.as_dvec3());
    let n = (b - a).cross(c - a).normalize_or_zero().as_vec3();
    let p = (a + (b - a) * u as f64 + (c - a) * v as f64).as_vec3();
    (n.to_array(), p.to_array())
}

/// The closest hit of every ray.
pub fn closest(s: &Structure, rays: RaySet<'_>) -> Closest {
    let n = rays.len();
    let mut out = Closest {
        t: vec![f32::INFINITY; n],
        triangle: vec![-1; n],
        u: vec![0.0; n],
        v: vec![0.0; n],
        normal: vec![0.0; 3 * n],
        point: vec![0.0; 3 * n],
    };
    let mesh = s.primitives().as_ref();
    out.t
        .par_chunks_mut(CHUNK)
        .zip(out.triangle.par_chunks_mut(CHUNK))
        .zip(out.u.par_chunks_mut(CHUNK))
        .zip(out.v.par_chunks_mut(CHUNK))
        .zip(out.normal.par_chunks_mut(3 * CHUNK))
        .zip(out.point.par_chunks_mut(3 * CHUNK))
        .enumerate()
        .for_each(|(c, (((((t, tri), u), v), nrm), pt))| {
            let base = c * CHUNK;
            let k = t.len();
            let mut batch = Vec::with_capacity(k);
            let mut t_max = Vec::with_capacity(k);
            let mut shift = Vec::with_capacity(k);
            for i in base..base + k {
                let (r, t1, s0) = rays.ray(i);
                batch.push(r);
                t_max.push(t1);
                shift.push(s0);
            }
            let mut hits: Vec<Option<Hit>> = vec![None; k];
            s.intersect_many(&batch, &t_max, &mut hits);
            for (j, h) in hits.iter().enumerate() {
                let Some(h) = h else { continue };
                t[j] = h.t + shift[j];
                tri[j] = h.prim as i64;
                (u[j], v[j]) = (h.u, h.v);
                let (nv, pv) = surface(mesh, h.prim, h.u, h.v);
                nrm[3 * j..3 * j + 3].copy_from_slice(&nv);
                pt[3 * j..3 * j + 3].copy_from_slice(&pv);
            }
        });
    out
}

/// Whether each ray hits anything in its interval (the structure's any-hit query: it stops at the
/// first hit it finds).
pub fn occluded(s: &Structure, rays: RaySet<'_>) -> Vec<bool> {
    let mut out = vec![false; rays.len()];
    out.par_chunks_mut(CHUNK).enumerate().for_each(|(c, o)| {
        let base = c * CHUNK;
        let (batch, t_max): (Vec<Ray>, Vec<f32>) = (base..base + o.len())
            .map(|i| {
                let (r, t1, _) = rays.ray(i);
                (r, t1)
            })
            .unzip();
        s.occluded_many(&batch, &t_max, o);
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
                    part.point.extend(surface(mesh, h.prim, h.u, h.v).1);
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
    // Whether the structure answers at all, asked once (an empty batch): every chunk then can.
    s.closest_points_many(&[], max_distance, &mut [])?;
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
            // Answers, as the empty batch above did.
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
