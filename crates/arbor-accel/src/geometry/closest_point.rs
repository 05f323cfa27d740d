//! The point of a triangle closest to a given point, by the Voronoi regions of its vertices, edges and
//! face (Ericson, "Real-Time Collision Detection", 2005, section 5.1.5): a handful of dot products, no
//! square root, exact for degenerate triangles too (a segment or a point gives its own closest point).
//!
//! Computed in `f64` (corners and point widened exactly), so the answer is as close to the true closest
//! point as the region decisions allow, and two guarantees hold whatever the rounding, which the
//! structures' closest-point queries build on (`accel/nearest.rs`):
//! - the point is a convex combination of the corners up to the rounding of that combination: the
//!   face region's weights are clamped to the triangle (a sliver's weights can come out a hair
//!   negative), the edge regions' parameters lie in `[0, 1]` by construction;
//! - the point lies inside the box of the three corners (it is clamped there), so inside every box
//!   that holds the triangle.

use crate::math::{DVec3, Vec3};

/// The point of triangle `(a, b, c)` closest to `p` (rounded to `f32` from [`closest_point_on_triangle_f64`]).
pub fn closest_point_on_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let [p, a, b, c] = [p, a, b, c].map(|v| v.as_dvec3());
    closest_point_on_triangle_f64(p, a, b, c).0.as_vec3()
}

/// The point of triangle `(a, b, c)` closest to `p`, and its barycentric weights `(u, v)` of `b` and
/// `c`: `u, v >= 0`, `u + v <= 1`, the point `a + u (b - a) + v (c - a)` up to rounding and the clamp
/// into the corners' box.
pub fn closest_point_on_triangle_f64(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> (DVec3, f64, f64) {
    let (q, u, v) = by_regions(p, a, b, c);
    (q.clamp(a.min(b).min(c), a.max(b).max(c)), u, v)
}

/// Ericson's region tests: the closest point (before the clamp) and its weights.
fn by_regions(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> (DVec3, f64, f64) {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, 0.0, 0.0);
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return (b, 1.0, 0.0);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        // In [0, 1]: `d1 - d3 >= d1 >= 0` holds after rounding too. So for the other edges.
        let t = d1 / (d1 - d3);
        return (a + ab * t, t, 0.0);
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return (c, 0.0, 1.0);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let t = d2 / (d2 - d6);
        return (a + ac * t, 0.0, t);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * t, 1.0 - t, t);
    }
    let denom = va + vb + vc;
    if denom.abs() > f64::MIN_POSITIVE {
        // Rounding (a sliver) can put the weights a hair outside the triangle: clamp them onto it.
        let (mut v, mut w) = ((vb / denom).max(0.0), (vc / denom).max(0.0));
        if v + w > 1.0 {
            (v, w) = (v / (v + w), w / (v + w));
        }
        return (a + ab * v + ac * w, v, w);
    }
    // A degenerate triangle whose regions all failed (collinear corners): the closest of its edges,
    // each as `s + t (e - s)` with `t` in [0, 1], and its weights.
    let on = |s: DVec3, e: DVec3| {
        let d = e - s;
        let len2 = d.length_squared();
        let t = if len2 > 0.0 { ((p - s).dot(d) / len2).clamp(0.0, 1.0) } else { 0.0 };
        (s + d * t, t)
    };
    let ((q_ab, t_ab), (q_bc, t_bc), (q_ca, t_ca)) = (on(a, b), on(b, c), on(c, a));
    let candidates = [(q_ab, t_ab, 0.0), (q_bc, 1.0 - t_bc, t_bc), (q_ca, 0.0, 1.0 - t_ca)];
    candidates
        .into_iter()
        .min_by(|x, y| (x.0 - p).length_squared().total_cmp(&(y.0 - p).length_squared()))
        .unwrap_or((a, 0.0, 0.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closest point by brute force: the triangle sampled on a fine barycentric grid.
    fn sampled(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> f32 {
        let n = 200;
        let mut best = f32::INFINITY;
        for i in 0..=n {
            for j in 0..=n - i {
                let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
                best = best.min((a + (b - a) * u + (c - a) * v - p).length());
            }
        }
        best
    }

    #[test]
    fn closest_point_matches_a_dense_sampling_in_every_region() {
        let (a, b, c) = (Vec3::new(0.0, 0.0, 0.0), Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.5, 1.5, 0.0));
        // Points above the face, beyond each vertex and beyond each edge.
        let probes = [
            Vec3::new(0.6, 0.4, 1.0),
            Vec3::new(-1.0, -1.0, 0.3),
            Vec3::new(3.0, -0.5, -0.2),
            Vec3::new(0.4, 2.5, 0.1),
            Vec3::new(1.0, -1.0, 0.5),
            Vec3::new(1.8, 1.2, -0.4),
            Vec3::new(-0.8, 0.9, 0.0),
        ];
        for p in probes {
            let q = closest_point_on_triangle(p, a, b, c);
            let (got, want) = ((q - p).length(), sampled(p, a, b, c));
            assert!(got <= want + 1e-6 && got >= want - 0.02, "{p}: {got} vs sampled {want}");
        }
    }

    #[test]
    fn closest_point_on_degenerate_triangles_is_on_their_segment_or_point() {
        let (a, b) = (Vec3::ZERO, Vec3::new(4.0, 0.0, 0.0));
        let q = closest_point_on_triangle(Vec3::new(1.0, 2.0, 0.0), a, b, Vec3::new(2.0, 0.0, 0.0));
        assert!((q - Vec3::new(1.0, 0.0, 0.0)).length() < 1e-6, "{q}");
        let q = closest_point_on_triangle(Vec3::new(1.0, 2.0, 3.0), a, a, a);
        assert_eq!(q, a);
    }

    #[test]
    fn closest_point_weights_name_the_point_and_stay_on_the_triangle() {
        let (a, b, c) = (DVec3::new(0.0, 0.0, 0.0), DVec3::new(2.0, 0.0, 0.0), DVec3::new(0.5, 1.5, 0.0));
        let probes = [
            (0.6, 0.4, 1.0),
            (-1.0, -1.0, 0.3),
            (3.0, -0.5, -0.2),
            (0.4, 2.5, 0.1),
            (1.0, -1.0, 0.5),
            (1.8, 1.2, -0.4),
        ];
        for (x, y, z) in probes {
            let (q, u, v) = closest_point_on_triangle_f64(DVec3::new(x, y, z), a, b, c);
            assert!(u >= 0.0 && v >= 0.0 && u + v <= 1.0, "({x}, {y}, {z}): weights {u}, {v}");
            assert!((a + (b - a) * u + (c - a) * v - q).length() < 1e-12, "({x}, {y}, {z}): {q} vs {u}, {v}");
        }
        // A sliver, queried all around: the point stays in the corners' box, the weights in the triangle.
        let (a, b, c) = (DVec3::new(0.0, 0.0, 0.0), DVec3::new(1e4, 1.0, 0.0), DVec3::new(2e4, 2.0 + 1e-9, 0.0));
        for k in 0..200 {
            let t = k as f64 / 10.0;
            let p = DVec3::new(t * 1e3, t.sin() * 1e-3 + t * 0.1, t.cos() * 1e-3);
            let (q, u, v) = closest_point_on_triangle_f64(p, a, b, c);
            assert!(u >= 0.0 && v >= 0.0 && u + v <= 1.0, "{p}: weights {u}, {v}");
            assert!(q.cmpge(a.min(b).min(c)).all() && q.cmple(a.max(b).max(c)).all(), "{p}: {q}");
        }
    }
}
