//! Exact triangle-box overlap by the separating axis theorem (Akenine-Möller 2001, "Fast 3D
//! triangle-box overlap testing"): a triangle and an axis-aligned box are disjoint exactly when their
//! projections are disjoint on one of 13 axes: the 3 box normals, the triangle's normal, and the 9
//! cross products of a triangle edge with a box edge.
//!
//! Used by structures that put a triangle in every cell it touches (the octree): there a false "no"
//! loses the triangle for rays through that cell, while a false "yes" only costs a reference. So:
//! - the box is closed: touching (a vertex on a face, a triangle lying in a face plane) is overlap;
//! - the box-normal axes compare the input coordinates directly, which is exact;
//! - the other 10 axes are evaluated in `f64` and only declare separation when the gap exceeds a
//!   tolerance ([`REL_TOL`]) relative to the magnitudes involved, far above the `f64` rounding of the
//!   products, so rounding can only turn a separation into a (conservative) overlap. Separation on any
//!   axis at all proves disjointness, so the rounding of the axes themselves does not matter;
//! - degenerate triangles (zero area, repeated vertices) give zero normal or zero cross products, which
//!   separate nothing; the remaining axes still contain a separating one for a segment or a point (the
//!   theorem holds for those degenerate polytopes: every candidate direction they need lies in the span
//!   of the edge cross products and the box normals). Boxes with zero extent on some axes are handled
//!   the same way (a flat box is a rectangle, a convex polygon);
//! - a NaN coordinate makes every comparison false, hence "overlap": never a miss.
//!
//! Cost: about 70 floating-point operations, branch-free except for early exits.

use crate::math::{Aabb, Vec3};

/// Gap, relative to the size of the terms of a projection, below which an axis is not trusted to
/// separate. The projections carry relative errors of a few `f64` ulps (1e-16); the inputs are `f32`
/// (1e-7), so 1e-12 is exact at `f32` resolution and safely above rounding.
const REL_TOL: f64 = 1e-12;

/// Whether triangle `(a, b, c)` has a point in the closed box `bx`: exact, or conservative ("yes")
/// within a relative 1e-12 of touching; see the module docs.
pub fn triangle_overlaps_box(a: Vec3, b: Vec3, c: Vec3, bx: &Aabb) -> bool {
    if bx.is_empty() {
        return false;
    }
    // Box normals: the triangle's bounds against the box, in the input precision (exact).
    for k in 0..3 {
        let (lo, hi) = (bx.min[k], bx.max[k]);
        if (a[k] > hi && b[k] > hi && c[k] > hi) || (a[k] < lo && b[k] < lo && c[k] < lo) {
            return false;
        }
    }
    let center = [0, 1, 2].map(|k| 0.5 * (f64::from(bx.min[k]) + f64::from(bx.max[k])));
    let half = [0, 1, 2].map(|k| 0.5 * (f64::from(bx.max[k]) - f64::from(bx.min[k])));
    let rel = |p: Vec3| [0, 1, 2].map(|k| f64::from(p[k]) - center[k]);
    let v = [rel(a), rel(b), rel(c)];
    let edges = [sub(v[1], v[0]), sub(v[2], v[1]), sub(v[0], v[2])];
    // The triangle's normal.
    if separates(cross(edges[0], edges[1]), &v, half) {
        return false;
    }
    // Edge x box axis: `e x unit_k`.
    for e in edges {
        for axis in [[0.0, e[2], -e[1]], [-e[2], 0.0, e[0]], [e[1], -e[0], 0.0]] {
            if separates(axis, &v, half) {
                return false;
            }
        }
    }
    true
}

/// True when `axis` separates the triangle `v` (relative to the box centre) from the box of
/// half-extents `half`, by more than the tolerance. A zero axis separates nothing.
#[inline]
fn separates(axis: [f64; 3], v: &[[f64; 3]; 3], half: [f64; 3]) -> bool {
    let p = v.map(|q| axis[0] * q[0] + axis[1] * q[1] + axis[2] * q[2]);
    let r: f64 = (0..3).map(|k| half[k] * axis[k].abs()).sum();
    let magnitude: f64 = (0..3).map(|k| axis[k].abs() * v.iter().map(|q| q[k].abs()).fold(0.0, f64::max)).sum();
    let tol = REL_TOL * (magnitude + r);
    let lo = p[0].min(p[1]).min(p[2]);
    let hi = p[0].max(p[1]).max(p[2]);
    lo > r + tol || hi < -r - tol
}

#[inline]
fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_box() -> Aabb {
        Aabb::new(Vec3::ZERO, Vec3::ONE)
    }

    fn v(x: f32, y: f32, z: f32) -> Vec3 {
        Vec3::new(x, y, z)
    }

    #[test]
    fn triangle_box_hand_worked_cases() {
        let b = unit_box();
        // Inside, crossing, containing the box's cross-section.
        assert!(triangle_overlaps_box(v(0.2, 0.2, 0.5), v(0.8, 0.2, 0.5), v(0.5, 0.8, 0.5), &b));
        assert!(triangle_overlaps_box(v(-5.0, -5.0, 0.5), v(10.0, -5.0, 0.5), v(-5.0, 10.0, 0.5), &b));
        // Bounds overlap but the plane passes beside the corner (x + y + z = 3.2 misses the box).
        assert!(!triangle_overlaps_box(v(3.2, 0.0, 0.0), v(0.0, 3.2, 0.0), v(0.0, 0.0, 3.2), &b));
        // The same plane through the corner (1, 1, 1) touches it; slightly nearer crosses it.
        assert!(triangle_overlaps_box(v(3.0, 0.0, 0.0), v(0.0, 3.0, 0.0), v(0.0, 0.0, 3.0), &b));
        assert!(triangle_overlaps_box(v(2.9, 0.0, 0.0), v(0.0, 2.9, 0.0), v(0.0, 0.0, 2.9), &b));
        // An edge passing beside an edge of the box: separated only by an edge-cross axis.
        assert!(!triangle_overlaps_box(v(2.6, -0.5, 0.5), v(-0.5, 2.6, 0.5), v(5.0, 5.0, 0.5), &b));
        assert!(triangle_overlaps_box(v(2.4, -0.5, 0.5), v(-0.5, 2.4, 0.5), v(5.0, 5.0, 0.5), &b));
        // Lying in a face plane (closed box), and just off it.
        assert!(triangle_overlaps_box(v(0.2, 0.2, 1.0), v(0.8, 0.2, 1.0), v(0.5, 0.8, 1.0), &b));
        assert!(!triangle_overlaps_box(v(0.2, 0.2, 1.01), v(0.8, 0.2, 1.01), v(0.5, 0.8, 1.01), &b));
        // A vertex on a corner from outside.
        assert!(triangle_overlaps_box(v(1.0, 1.0, 1.0), v(2.0, 1.0, 1.0), v(2.0, 2.0, 3.0), &b));
    }

    #[test]
    fn triangle_box_degenerate_triangles_and_flat_boxes() {
        let b = unit_box();
        // Segments: crossing the box, beside it diagonally, through a corner.
        assert!(triangle_overlaps_box(v(-1.0, 0.5, 0.5), v(2.0, 0.5, 0.5), v(0.5, 0.5, 0.5), &b));
        assert!(!triangle_overlaps_box(v(2.6, -0.5, 0.5), v(-0.5, 2.6, 0.5), v(2.6, -0.5, 0.5), &b));
        assert!(triangle_overlaps_box(v(2.0, 0.0, 0.5), v(0.0, 2.0, 0.5), v(2.0, 0.0, 0.5), &b));
        // Points.
        assert!(triangle_overlaps_box(v(1.0, 0.3, 0.0), v(1.0, 0.3, 0.0), v(1.0, 0.3, 0.0), &b));
        assert!(!triangle_overlaps_box(v(1.1, 0.3, 0.0), v(1.1, 0.3, 0.0), v(1.1, 0.3, 0.0), &b));
        // A flat box (a square at z = 0.5) crossed by a triangle, and a point box.
        let flat = Aabb::new(v(0.0, 0.0, 0.5), v(1.0, 1.0, 0.5));
        assert!(triangle_overlaps_box(v(0.5, 0.5, 0.0), v(0.6, 0.5, 1.0), v(0.5, 0.6, 1.0), &flat));
        assert!(!triangle_overlaps_box(v(1.5, 0.5, 0.0), v(1.6, 0.5, 1.0), v(1.5, 0.6, 1.0), &flat));
        let point = Aabb::point(v(0.25, 0.25, 0.0));
        assert!(triangle_overlaps_box(v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0), &point));
        // In the triangle's plane, just outside its hypotenuse.
        let out = Aabb::point(v(0.5, 0.5001, 0.0));
        assert!(!triangle_overlaps_box(v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0), &out));
        // Empty boxes hold nothing; NaN corners are conservatively "yes".
        assert!(!triangle_overlaps_box(v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0), &Aabb::EMPTY));
        assert!(triangle_overlaps_box(v(f32::NAN, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0), &b));
    }

    /// Reference: the triangle clipped by the box's six planes (Sutherland-Hodgman in `f64`), with the
    /// planes moved outwards by `grow` (negative shrinks the box); true when anything is left.
    fn clip_overlaps(t: [Vec3; 3], b: &Aabb, grow: f64) -> bool {
        let mut poly: Vec<[f64; 3]> = t.iter().map(|p| [0, 1, 2].map(|k| f64::from(p[k]))).collect();
        for k in 0..3 {
            for (sign, plane) in [(1.0, f64::from(b.max[k]) + grow), (-1.0, f64::from(b.min[k]) - grow)] {
                let inside = |p: &[f64; 3]| sign * (p[k] - plane) <= 0.0;
                let mut out = Vec::new();
                for i in 0..poly.len() {
                    let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
                    if inside(&p) {
                        out.push(p);
                    }
                    if inside(&p) != inside(&q) {
                        let s = (plane - p[k]) / (q[k] - p[k]);
                        out.push([0, 1, 2].map(|j| p[j] + s * (q[j] - p[j])));
                    }
                }
                poly = out;
                if poly.is_empty() {
                    return false;
                }
            }
        }
        true
    }

    struct Rng(u64);
    impl Rng {
        fn f32(&mut self) -> f32 {
            self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (self.0 >> 40) as f32 / (1u64 << 24) as f32
        }
        fn point(&mut self, lo: f32, hi: f32) -> Vec3 {
            Vec3::new(lo + (hi - lo) * self.f32(), lo + (hi - lo) * self.f32(), lo + (hi - lo) * self.f32())
        }
        /// Coordinates on a coarse lattice (many exact touches), or free.
        fn coord_point(&mut self) -> Vec3 {
            if self.f32() < 0.5 {
                (self.point(-1.0, 3.0) * 4.0).round() / 4.0
            } else {
                self.point(-1.0, 3.0)
            }
        }
    }

    #[test]
    fn triangle_box_matches_clipping_reference_on_random_cases() {
        let mut rng = Rng(7);
        let mut agree = 0;
        for i in 0..200_000 {
            let mut t = [rng.coord_point(), rng.coord_point(), rng.coord_point()];
            match i % 5 {
                0 => t[2] = t[0] + (t[1] - t[0]) * rng.f32(), // a segment
                1 => t[1] = t[0],                             // a segment with a repeated vertex
                2 => t = [t[0]; 3],                           // a point
                _ => {}
            }
            let (p, q) = (rng.coord_point(), rng.coord_point());
            let mut b = Aabb::new(p.min(q), p.max(q));
            if i % 7 == 0 {
                b.max.y = b.min.y; // flat box
            }
            let sat = triangle_overlaps_box(t[0], t[1], t[2], &b);
            let tol = 1e-5;
            if clip_overlaps(t, &b, -tol) {
                assert!(sat, "missed overlap: {t:?} {b:?}");
            }
            if sat {
                assert!(clip_overlaps(t, &b, tol), "false overlap: {t:?} {b:?}");
            }
            agree += usize::from(sat == clip_overlaps(t, &b, 0.0));
        }
        assert!(agree > 199_000, "only {agree} exact agreements");
    }

    #[test]
    fn triangle_box_finds_every_sampled_point_inside() {
        let mut rng = Rng(11);
        for _ in 0..20_000 {
            let t = [rng.point(-1.0, 2.0), rng.point(-1.0, 2.0), rng.point(-1.0, 2.0)];
            let c = rng.point(-0.5, 1.5);
            let h = rng.point(0.0, 0.3);
            let b = Aabb::new(c - h, c + h);
            let sat = triangle_overlaps_box(t[0], t[1], t[2], &b);
            for _ in 0..64 {
                let (mut s, mut r) = (rng.f32(), rng.f32());
                if s + r > 1.0 {
                    (s, r) = (1.0 - s, 1.0 - r);
                }
                let p = t[0] + s * (t[1] - t[0]) + r * (t[2] - t[0]);
                if b.contains(&Aabb::point(p)) {
                    assert!(sat, "sample {p:?} of {t:?} is in {b:?}");
                }
            }
        }
    }
}
