//! Watertight ray-triangle intersection (Woop, Benthin and Wald, "Watertight Ray/Triangle
//! Intersection", JCGT 2013), in the form of pbrt-v4's `IntersectTriangle`.
//!
//! Why this and not Möller-Trumbore: the edge functions are evaluated in a ray-aligned frame where a
//! point on an edge shared by two triangles gets the same value (of opposite sign) from both, so a ray
//! can never slip between neighbours; rays from inside a closed mesh always hit it. Edge functions that
//! round to exactly zero are recomputed in double precision, each on its own (so that an edge's value
//! depends on its two vertices and the ray only). The returned `t` is conservatively positive:
//! a hit closer than the floating-point error of `t` itself is rejected.

use crate::math::{Ray, Vec3};

/// A hit on a triangle: distance and the barycentric weights of its second and third vertex.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriHit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// Weight of vertex 1 (vertex 0 has `1 - b1 - b2`).
    pub b1: f32,
    /// Weight of vertex 2.
    pub b2: f32,
}

#[inline]
fn permute(v: Vec3, kx: usize, ky: usize, kz: usize) -> Vec3 {
    Vec3::new(v[kx], v[ky], v[kz])
}

/// The axis of `d`'s largest magnitude, the later of equal ones (the axis [`RayFrame`] divides by),
/// without branches: a query on incoherent rays that branched on it would mispredict about half the
/// time.
#[inline]
pub fn major_axis(d: Vec3) -> usize {
    let a = d.abs();
    let x_wins = a.x > a.y && a.x > a.z;
    let y_over_z = a.y > a.z;
    (!x_wins as usize) * (2 - y_over_z as usize)
}

/// The part of the watertight test that depends only on the ray (the paper computes it once per ray):
/// the axis permutation that makes the direction's largest component `z`, and the shear that maps the
/// direction onto `+z`. Structures build it once per query and test every triangle with
/// [`intersect_triangle_in`]; the arithmetic is the same, so the hits are bit for bit those of
/// [`intersect_triangle`].
#[derive(Debug, Clone, Copy)]
pub struct RayFrame {
    pub(crate) origin: Vec3,
    pub(crate) dir: Vec3,
    pub(crate) cull_backfaces: bool,
    pub(crate) kx: usize,
    pub(crate) ky: usize,
    pub(crate) kz: usize,
    pub(crate) sx: f32,
    pub(crate) sy: f32,
    pub(crate) sz: f32,
}

impl RayFrame {
    /// The frame of `ray`.
    #[inline]
    pub fn new(ray: &Ray) -> Self {
        // The axis of `major_axis`, chosen with branches: scene primitives build a frame per triangle
        // test, where the branches predict well and the branch-free form's longer chain shows
        // (docs/performance.md).
        let ad = ray.dir.abs();
        let kz = if ad.x > ad.y && ad.x > ad.z {
            0
        } else if ad.y > ad.z {
            1
        } else {
            2
        };
        Self::with_major(ray, kz)
    }

    /// The frame of `ray` whose [`major_axis`] is already known to be `kz` (a traversal computes it
    /// for its box test): no branch on the direction, which incoherent rays would mispredict. `kz`
    /// must be `major_axis(ray.dir)`, or the hits are not those of [`intersect_triangle`].
    #[inline]
    pub fn with_major(ray: &Ray, kz: usize) -> Self {
        const NEXT: [usize; 3] = [1, 2, 0];
        let (kx, ky) = (NEXT[kz], NEXT[NEXT[kz]]);
        let d = permute(ray.dir, kx, ky, kz);
        let sz = 1.0 / d.z;
        let sx = -d.x * sz;
        let sy = -d.y * sz;
        RayFrame { origin: ray.origin, dir: ray.dir, cull_backfaces: ray.cull_backfaces, kx, ky, kz, sx, sy, sz }
    }
}

/// The hit of `ray` with triangle `(p0, p1, p2)` in `(0, t_max)`, if any. With `ray.cull_backfaces`,
/// triangles whose counter-clockwise side faces away from the ray are skipped.
#[inline]
pub fn intersect_triangle(ray: &Ray, p0: Vec3, p1: Vec3, p2: Vec3, t_max: f32) -> Option<TriHit> {
    intersect_triangle_in(&RayFrame::new(ray), p0, p1, p2, t_max)
}

/// [`intersect_triangle`] for a ray whose [`RayFrame`] is already known (always inlined: it is the
/// body of every structure's leaf loop).
#[inline(always)]
pub fn intersect_triangle_in(f: &RayFrame, p0: Vec3, p1: Vec3, p2: Vec3, t_max: f32) -> Option<TriHit> {
    if f.cull_backfaces && f.dir.dot((p1 - p0).cross(p2 - p0)) >= 0.0 {
        return None;
    }
    let (kx, ky, kz) = (f.kx, f.ky, f.kz);
    let mut a = permute(p0 - f.origin, kx, ky, kz);
    let mut b = permute(p1 - f.origin, kx, ky, kz);
    let mut c = permute(p2 - f.origin, kx, ky, kz);
    let (a0, b0, c0) = (a, b, c);

    let (sx, sy, sz) = (f.sx, f.sy, f.sz);
    a.x += sx * a.z;
    a.y += sy * a.z;
    b.x += sx * b.z;
    b.y += sy * b.z;
    c.x += sx * c.z;
    c.y += sy * c.z;

    let mut e0 = b.x * c.y - b.y * c.x;
    let mut e1 = c.x * a.y - c.y * a.x;
    let mut e2 = a.x * b.y - a.y * b.x;
    if e0 == 0.0 || e1 == 0.0 || e2 == 0.0 {
        [e0, e1, e2] = zero_edges_f64(permute(f.dir, kx, ky, kz), [a0, b0, c0], [e0, e1, e2]);
    }
    if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0) {
        return None;
    }
    let det = e0 + e1 + e2;
    if det == 0.0 || !det.is_finite() {
        return None;
    }

    a.z *= sz;
    b.z *= sz;
    c.z *= sz;
    let t_scaled = e0 * a.z + e1 * b.z + e2 * c.z;
    // Early outs on the scaled t. The far one is widened by a few ulps: `t_max * det` and the final
    // `t_scaled * (1 / det)` round differently, and only the final `t < t_max` may decide, or a hit at
    // `t` would vanish for `t_max` just above `t` (found by fuzzing; structures query exactly there).
    let far = t_max * det * (1.0 + 4.0 * f32::EPSILON);
    if det < 0.0 && (t_scaled >= 0.0 || t_scaled < far) {
        return None;
    }
    if det > 0.0 && (t_scaled <= 0.0 || t_scaled > far) {
        return None;
    }
    let inv_det = 1.0 / det;
    let t = t_scaled * inv_det;
    // Negated so that a NaN `t` or `t_max` is a miss too.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    if !(t < t_max) {
        return None;
    }

    // Reject hits whose t is within its own rounding error of zero (pbrt-v4, section 6.8.4).
    let gamma = |n: f32| (n * f32::EPSILON * 0.5) / (1.0 - n * f32::EPSILON * 0.5);
    let max_zt = Vec3::new(a.z, b.z, c.z).abs().max_element();
    let delta_z = gamma(3.0) * max_zt;
    let max_xt = Vec3::new(a.x, b.x, c.x).abs().max_element();
    let max_yt = Vec3::new(a.y, b.y, c.y).abs().max_element();
    let delta_x = gamma(5.0) * (max_xt + max_zt);
    let delta_y = gamma(5.0) * (max_yt + max_zt);
    let delta_e = 2.0 * (gamma(2.0) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
    let max_e = Vec3::new(e0, e1, e2).abs().max_element();
    let delta_t = 3.0 * (gamma(3.0) * max_e * max_zt + delta_e * max_zt + delta_z * max_e) * inv_det.abs();
    if t <= delta_t {
        return None;
    }
    Some(TriHit { t, b1: e1 * inv_det, b2: e2 * inv_det })
}

/// The edge functions `e`, each one that is exactly zero in single precision recomputed in double
/// precision, sheared in double too (Woop et al.'s fallback, decided edge by edge).
///
/// Why edge by edge: an edge's value must depend only on its two corners and the ray, so that the edge
/// shared by two triangles gets the same magnitude with opposite signs from both, whatever their other
/// edges. A nonzero single value has the exact sign of the edge function of the corners as sheared in
/// single precision (the products round monotonically, and the difference of two floats has the exact
/// sign); a zero means the ray meets that edge's line there, or its two products round alike, and the
/// double value only picks a side of that line: the hit goes to one of the two triangles sharing the
/// edge, or to both when it is zero again. Recomputing all three edges of a triangle when one is zero
/// would mix the two shears: they differ by as much as a ray aimed at a vertex misses it
/// by, so the edge shared with a neighbour that stayed in single precision could get the same sign from
/// both, and the ray slipped through the vertex's fan (about 1% of oblique rays aimed at the vertices of
/// an integer grid; `accel/watertight_tests.rs`). pbrt-v4 recomputes from the single-precision
/// sheared corners instead, which is consistent but not the fix for the case below.
///
/// Shearing again matters at tiny scales: a single-precision `sx * a.z` can underflow to zero and put a
/// vertex exactly on a ray that passes it at 1e-79, which no box test of the true ray would reach (found
/// by the conformance suite). A nonzero double value that underflows in single precision keeps its sign
/// as the smallest subnormal.
#[cold]
fn zero_edges_f64(d: Vec3, [a, b, c]: [Vec3; 3], e: [f32; 3]) -> [f32; 3] {
    let sz = 1.0 / d.z as f64;
    let (sx, sy) = (-d.x as f64 * sz, -d.y as f64 * sz);
    let shear = |p: Vec3| (p.x as f64 + sx * p.z as f64, p.y as f64 + sy * p.z as f64);
    let [a, b, c] = [shear(a), shear(b), shear(c)];
    let edge = |e: f32, (px, py): (f64, f64), (qx, qy): (f64, f64)| {
        if e != 0.0 {
            return e;
        }
        let e = px * qy - py * qx;
        let f = e as f32;
        if f == 0.0 && e != 0.0 {
            f32::from_bits(1).copysign(e.signum() as f32)
        } else {
            f
        }
    };
    [edge(e[0], b, c), edge(e[1], c, a), edge(e[2], a, b)]
}

#[cfg(test)]
mod tests {
    use super::*;

    const P0: Vec3 = Vec3::new(-1.0, -1.0, 0.0);
    const P1: Vec3 = Vec3::new(1.0, -1.0, 0.0);
    const P2: Vec3 = Vec3::new(0.0, 1.0, 0.0);

    #[test]
    fn major_axis_is_the_largest_magnitude_later_of_ties() {
        let cases = [
            (Vec3::new(3.0, -1.0, 2.0), 0),
            (Vec3::new(1.0, -3.0, 2.0), 1),
            (Vec3::new(1.0, 2.0, -3.0), 2),
            (Vec3::new(2.0, -2.0, 1.0), 1),
            (Vec3::new(2.0, 1.0, -2.0), 2),
            (Vec3::new(1.0, 2.0, 2.0), 2),
            (Vec3::splat(1.0), 2),
            (Vec3::new(f32::NAN, 1.0, 0.5), 1),
            (Vec3::new(1.0, 0.0, 0.0), 0),
        ];
        for (d, want) in cases {
            assert_eq!(major_axis(d), want, "{d:?}");
            // The traversal's box slack rests on this being the axis the watertight test divides by.
            let ray = Ray { origin: Vec3::ZERO, dir: d, inv_dir: d.recip(), time: 0.0, cull_backfaces: false };
            assert_eq!(RayFrame::new(&ray).kz, want, "{d:?}");
        }
    }

    #[test]
    fn triangle_hit_reports_distance_and_barycentrics() {
        let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::new(0.0, 0.0, -1.0));
        let h = intersect_triangle(&ray, P0, P1, P2, f32::INFINITY).unwrap();
        assert!((h.t - 5.0).abs() < 1e-6);
        let p = (1.0 - h.b1 - h.b2) * P0 + h.b1 * P1 + h.b2 * P2;
        assert!(p.abs_diff_eq(Vec3::ZERO, 1e-6));
    }

    #[test]
    fn triangle_miss_outside_and_beyond_t_max_and_behind() {
        let ray = Ray::new(Vec3::new(2.0, 0.0, 5.0), Vec3::new(0.0, 0.0, -1.0));
        assert!(intersect_triangle(&ray, P0, P1, P2, f32::INFINITY).is_none());
        let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::new(0.0, 0.0, -1.0));
        assert!(intersect_triangle(&ray, P0, P1, P2, 4.9).is_none());
        let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::new(0.0, 0.0, 1.0));
        assert!(intersect_triangle(&ray, P0, P1, P2, f32::INFINITY).is_none());
    }

    #[test]
    fn triangle_backface_culling_only_when_asked() {
        let from_back = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::new(0.0, 0.0, 1.0));
        assert!(intersect_triangle(&from_back, P0, P1, P2, f32::INFINITY).is_some());
        assert!(intersect_triangle(&from_back.with_culling(true), P0, P1, P2, f32::INFINITY).is_none());
        let from_front = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::new(0.0, 0.0, -1.0));
        assert!(intersect_triangle(&from_front.with_culling(true), P0, P1, P2, f32::INFINITY).is_some());
    }

    #[test]
    fn triangle_shared_edge_is_hit_by_exactly_one_side_or_both() {
        // Two triangles sharing the edge x = 0; rays straight down that edge must hit at least one.
        let q0 = Vec3::new(0.0, -1.0, 0.0);
        let q1 = Vec3::new(0.0, 1.0, 0.0);
        let left = Vec3::new(-1.0, 0.3, 0.0);
        let right = Vec3::new(1.0, -0.2, 0.0);
        for k in 0..1000 {
            let y = -0.999 + k as f32 * 0.001998;
            let ray = Ray::new(Vec3::new(0.0, y, 3.7), Vec3::new(0.0, 0.0, -1.0));
            let a = intersect_triangle(&ray, q0, q1, left, f32::INFINITY);
            let b = intersect_triangle(&ray, q1, q0, right, f32::INFINITY);
            assert!(a.is_some() || b.is_some(), "ray at y={y} slipped through the shared edge");
        }
    }

    #[test]
    fn triangle_degenerate_and_nan_rays_hit_nothing() {
        let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::new(0.0, 0.0, -1.0));
        assert!(intersect_triangle(&ray, P0, P0, P2, f32::INFINITY).is_none());
        let nan = Ray::new(Vec3::new(f32::NAN, 0.0, 5.0), Vec3::new(0.0, 0.0, -1.0));
        assert!(intersect_triangle(&nan, P0, P1, P2, f32::INFINITY).is_none());
        let in_plane = Ray::new(Vec3::new(-5.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0));
        assert!(intersect_triangle(&in_plane, P0, P1, P2, f32::INFINITY).is_none());
    }

    #[test]
    fn triangle_hit_at_subnormal_t_is_kept_just_above_it() {
        // Scaled triangles so that `det` is not a power of two and `t_max * det` rounds as a subnormal.
        for k in 1..200 {
            let s = 0.3 + k as f32 * 0.037;
            let (p0, p1, p2) = (P0 * s, P1 * s, P2 * (s * 1.3));
            let ray = Ray::new(Vec3::new(0.01, 0.02, 1e-40 * k as f32), Vec3::new(0.0, 0.0, -1.0 - k as f32 * 0.01));
            let hit = intersect_triangle(&ray, p0, p1, p2, f32::INFINITY).expect("hit with t_max infinite");
            let above = hit.t.next_up();
            let again = intersect_triangle(&ray, p0, p1, p2, above).map(|h| h.t);
            assert_eq!(again, Some(hit.t), "scale {s}: hit at t {:e}, none below t_max {above:e}", hit.t);
        }
    }
}
