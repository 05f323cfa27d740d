//! The point of a triangle closest to a given point, by the Voronoi regions of its vertices, edges and
//! face (Ericson, "Real-Time Collision Detection", 2005, section 5.1.5): a handful of dot products, no
//! square root, exact for degenerate triangles too (a segment or a point gives its own closest point).

use crate::math::Vec3;

/// The point of triangle `(a, b, c)` closest to `p`.
pub fn closest_point_on_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = va + vb + vc;
    // A degenerate triangle whose regions all failed (collinear corners): the closest of its edges.
    if denom.abs() <= f32::MIN_POSITIVE {
        let on = |s: Vec3, e: Vec3| {
            let d = e - s;
            let t = if d.length_squared() > 0.0 { ((p - s).dot(d) / d.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
            s + d * t
        };
        let candidates = [on(a, b), on(b, c), on(c, a)];
        return candidates
            .into_iter()
            .min_by(|x, y| (*x - p).length_squared().total_cmp(&(*y - p).length_squared()))
            .unwrap_or(a);
    }
    let (v, w) = (vb / denom, vc / denom);
    a + ab * v + ac * w
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
}
