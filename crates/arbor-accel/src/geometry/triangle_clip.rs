//! The bounds of a triangle clipped to an axis-aligned box: the "perfect splits" of SAH kd-trees
//! (Havran 2000; Wald and Havran 2006, section 4.3), where a primitive straddling a split plane
//! contributes split candidates from the part of it inside each child, not from its whole box.
//!
//! Algorithm: Sutherland-Hodgman clipping of the triangle, as a polygon of up to 9 vertices, against
//! the six planes of the box, then the box of what is left.
//!
//! Robustness (the result must never be smaller than the true clipped part, or a kd-tree leaf would
//! miss a primitive it touches):
//! - the clipping runs in double precision against the box grown by a margin far larger than the
//!   double rounding of the intersection points ([`MARGIN`] times the largest coordinate involved),
//!   so the polygon kept is a superset of the true one; its box is rounded outward to `f32` and then
//!   cut by the exact box and the triangle's own bounds, which the true part lies in anyway. The
//!   result is therefore within a relative ~1e-9 of the exact clipped bounds, and never inside them;
//! - inside tests are inclusive, so a triangle that only touches the box (a corner on a face, or the
//!   whole triangle in a face's plane) gives a flat or point box on that face rather than nothing;
//! - degenerate triangles (repeated or collinear corners) are polygons like any other;
//! - a triangle with a non-finite corner falls back to its bounds cut by the box (conservative).
//!
//! The result is [`Aabb::EMPTY`] exactly when the triangle misses the box (beyond the margin).
//! Cost: at most 6 passes over at most 9 vertices, no allocation.

use crate::math::{Aabb, Vec3};

/// Growth of the clipping box relative to the largest coordinate magnitude (2^-30, about 1e-9).
/// Double-precision clipping errs by a few 1e-16 of that magnitude, so the grown box's slack covers
/// it with a wide safety factor, while staying far below `f32` resolution for the size of the
/// geometry.
const MARGIN: f64 = 1.0 / (1u64 << 30) as f64;

/// Most vertices the polygon can have: each of the 6 planes adds at most one to the triangle's 3.
const MAX_VERTS: usize = 9;

/// Bounds of the part of triangle `(a, b, c)` inside `bx` (boundaries included): conservative, never
/// smaller than the exact clipped part; [`Aabb::EMPTY`] when the triangle misses the box.
pub fn clip_triangle_bounds(a: Vec3, b: Vec3, c: Vec3, bx: &Aabb) -> Aabb {
    let tri = Aabb::from_points([a, b, c]);
    let cut = tri.intersection(*bx);
    if cut.is_empty() {
        return Aabb::EMPTY;
    }
    if !(a.is_finite() && b.is_finite() && c.is_finite() && bx.min.is_finite() && bx.max.is_finite()) {
        return cut;
    }
    // Nothing to clip when the triangle lies inside the box.
    if bx.contains(&tri) {
        return tri;
    }
    let scale = [a, b, c, bx.min, bx.max].iter().map(|p| p.abs().max_element()).fold(0.0f32, f32::max) as f64;
    let grow = scale * MARGIN;
    let mut poly = Polygon::new([a, b, c].map(|p| p.as_dvec3().to_array()));
    for axis in 0..3 {
        poly = poly.clip(axis, bx.min[axis] as f64 - grow, 1.0);
        poly = poly.clip(axis, bx.max[axis] as f64 + grow, -1.0);
        if poly.len == 0 {
            return Aabb::EMPTY;
        }
    }
    let (lo, hi) = poly.bounds();
    let outward = Aabb::new(
        Vec3::new(round_down(lo[0]), round_down(lo[1]), round_down(lo[2])),
        Vec3::new(round_up(hi[0]), round_up(hi[1]), round_up(hi[2])),
    );
    outward.intersection(cut)
}

/// A convex polygon of at most [`MAX_VERTS`] vertices in double precision.
#[derive(Clone, Copy)]
struct Polygon {
    verts: [[f64; 3]; MAX_VERTS],
    len: usize,
}

impl Polygon {
    fn new(tri: [[f64; 3]; 3]) -> Self {
        let mut verts = [[0.0; 3]; MAX_VERTS];
        verts[..3].copy_from_slice(&tri);
        Polygon { verts, len: 3 }
    }

    /// The part on the side `sign * (x[axis] - plane) >= 0` (one Sutherland-Hodgman pass).
    fn clip(&self, axis: usize, plane: f64, sign: f64) -> Polygon {
        let mut out = Polygon { verts: [[0.0; 3]; MAX_VERTS], len: 0 };
        let dist = |p: &[f64; 3]| sign * (p[axis] - plane);
        for i in 0..self.len {
            let p = self.verts[i];
            let q = self.verts[(i + 1) % self.len];
            let (dp, dq) = (dist(&p), dist(&q));
            if dp >= 0.0 {
                out.push(p);
            }
            // The edge crosses the plane strictly: add the crossing, with the clipped coordinate
            // set exactly on the plane.
            if (dp > 0.0 && dq < 0.0) || (dp < 0.0 && dq > 0.0) {
                let t = dp / (dp - dq);
                let mut x = [0.0; 3];
                for k in 0..3 {
                    x[k] = p[k] + t * (q[k] - p[k]);
                }
                x[axis] = plane;
                out.push(x);
            }
        }
        out
    }

    fn push(&mut self, p: [f64; 3]) {
        // A convex polygon clipped by one plane gains at most one vertex, so this never overflows;
        // the check only guards against a logic error.
        if self.len < MAX_VERTS {
            self.verts[self.len] = p;
            self.len += 1;
        }
    }

    fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for v in &self.verts[..self.len] {
            for k in 0..3 {
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
            }
        }
        (lo, hi)
    }
}

/// The largest `f32` not above `x`.
fn round_down(x: f64) -> f32 {
    let f = x as f32;
    if f as f64 > x {
        f.next_down()
    } else {
        f
    }
}

/// The smallest `f32` not below `x`.
fn round_up(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) < x {
        f.next_up()
    } else {
        f
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit() -> Aabb {
        Aabb::new(Vec3::ZERO, Vec3::ONE)
    }

    /// Equal within the clipping margin.
    fn close(a: Aabb, b: Aabb) -> bool {
        a.min.abs_diff_eq(b.min, 1e-6) && a.max.abs_diff_eq(b.max, 1e-6)
    }

    #[test]
    fn triangle_clip_inside_box_is_its_bounds() {
        let (a, b, c) = (Vec3::splat(0.1), Vec3::new(0.9, 0.2, 0.3), Vec3::new(0.4, 0.8, 0.7));
        assert_eq!(clip_triangle_bounds(a, b, c, &unit()), Aabb::from_points([a, b, c]));
    }

    #[test]
    fn triangle_clip_cuts_a_corner_exactly() {
        // The triangle x + y = 1.5 (z = 0.5 plane) from (1.5,0) to (0,1.5): inside the unit box only
        // the segment between (1, 0.5) and (0.5, 1) and the area below it remain.
        let a = Vec3::new(0.0, 0.0, 0.5);
        let b = Vec3::new(1.5, 0.0, 0.5);
        let c = Vec3::new(0.0, 1.5, 0.5);
        let got = clip_triangle_bounds(a, b, c, &unit());
        assert!(close(got, Aabb::new(Vec3::new(0.0, 0.0, 0.5), Vec3::new(1.0, 1.0, 0.5))), "{got:?}");
        // A diagonal triangle whose box covers the unit box but whose far corner region is empty.
        let a = Vec3::new(-1.0, 0.0, 0.0);
        let b = Vec3::new(0.0, -1.0, 0.0);
        let c = Vec3::new(-1.0, -1.0, 1.0);
        let box2 = Aabb::new(Vec3::splat(-0.75), Vec3::splat(0.0));
        let got = clip_triangle_bounds(a, b, c, &box2);
        // Points of the triangle: (-1 + s, -s - t, t) with s, t >= 0, s + t <= 1. In the box: z = t <= 0
        // forces t = 0, x >= -0.75 gives s >= 0.25, y >= -0.75 gives s <= 0.75: a segment in z = 0.
        let want = Aabb::new(Vec3::new(-0.75, -0.75, 0.0), Vec3::new(-0.25, -0.25, 0.0));
        assert!(close(got, want), "{got:?}");
    }

    #[test]
    fn triangle_clip_missing_the_box_is_empty() {
        // Bounds overlap the box, the triangle itself passes beside it.
        let a = Vec3::new(1.2, -0.5, 0.5);
        let b = Vec3::new(2.0, 0.5, 0.5);
        let c = Vec3::new(1.5, -1.0, 0.5);
        assert!(clip_triangle_bounds(a, b, c, &Aabb::new(Vec3::ZERO, Vec3::splat(1.55))).is_empty());
        let far = [Vec3::splat(5.0), Vec3::splat(6.0), Vec3::new(5.0, 6.0, 5.0)];
        assert!(clip_triangle_bounds(far[0], far[1], far[2], &unit()).is_empty());
    }

    #[test]
    fn triangle_clip_in_a_face_plane_and_touching_keeps_a_flat_box() {
        let (a, b, c) = (Vec3::new(-1.0, -1.0, 1.0), Vec3::new(3.0, -1.0, 1.0), Vec3::new(-1.0, 3.0, 1.0));
        let got = clip_triangle_bounds(a, b, c, &unit());
        assert_eq!(got, Aabb::new(Vec3::new(0.0, 0.0, 1.0), Vec3::ONE));
        // Touching the box at one corner only.
        let (a, b, c) = (Vec3::ONE, Vec3::new(2.0, 1.0, 1.0), Vec3::new(1.0, 2.0, 2.0));
        let got = clip_triangle_bounds(a, b, c, &unit());
        assert!(!got.is_empty() && got.contains(&Aabb::point(Vec3::ONE)), "{got:?}");
    }

    #[test]
    fn triangle_clip_handles_degenerate_and_non_finite_triangles() {
        let p = Vec3::new(0.5, 0.5, 0.5);
        assert_eq!(clip_triangle_bounds(p, p, p, &unit()), Aabb::point(p));
        // A segment from outside to outside through the box.
        let (a, b) = (Vec3::new(-1.0, 0.5, 0.5), Vec3::new(2.0, 0.5, 0.5));
        let got = clip_triangle_bounds(a, a, b, &unit());
        assert!(close(got, Aabb::new(Vec3::new(0.0, 0.5, 0.5), Vec3::new(1.0, 0.5, 0.5))), "{got:?}");
        let nan = Vec3::new(f32::NAN, 0.5, 0.5);
        let got = clip_triangle_bounds(a, b, nan, &unit());
        assert!(got.contains(&Aabb::new(Vec3::new(0.0, 0.5, 0.5), Vec3::new(1.0, 0.5, 0.5))));
    }

    use crate::test_rng::Rng;

    #[test]
    fn triangle_clip_contains_every_inside_point_and_stays_within_bounds() {
        let mut rng = Rng(0x5eed_1234_abcd_0001);
        for (round, (offset, scale)) in
            [(0.0, 1.0), (1e5, 1.0), (0.0, 1e-4), (-3.0, 20.0)].iter().cycle().take(800).enumerate()
        {
            let map = |p: Vec3| p * *scale + Vec3::splat(*offset);
            let [a, b, c] = [0; 3].map(|_| map(rng.vec3() * 3.0 - 1.0));
            let lo = map(rng.vec3());
            let hi = lo + rng.vec3() * *scale;
            let bx = Aabb::new(lo, hi);
            let got = clip_triangle_bounds(a, b, c, &bx);
            let limit = Aabb::from_points([a, b, c]).intersection(bx);
            assert!(limit.contains(&got), "round {round}: {got:?} outside {limit:?}");
            for _ in 0..400 {
                let (mut u, mut v) = (rng.f32(), rng.f32());
                if u + v > 1.0 {
                    (u, v) = (1.0 - u, 1.0 - v);
                }
                let p = a + u * (b - a) + v * (c - a);
                if bx.contains(&Aabb::point(p)) {
                    assert!(got.contains(&Aabb::point(p)), "round {round}: {p:?} missing from {got:?}");
                }
            }
        }
    }

    #[test]
    fn triangle_clip_rounds_outward_to_the_neighbouring_float() {
        let third = 1.0f64 / 3.0;
        let (down, up) = (round_down(third), round_up(third));
        assert!((down as f64) <= third && (up as f64) >= third && up == down.next_up());
        assert_eq!(round_down(0.5).to_bits(), 0.5f32.to_bits(), "exact values stay");
        assert_eq!(round_up(0.5).to_bits(), 0.5f32.to_bits());
        let tiny = f64::MIN_POSITIVE;
        assert_eq!((round_down(tiny).to_bits(), round_up(tiny).to_bits()), (0, 1), "below the subnormals");
        assert_eq!((round_down(-tiny).to_bits(), round_up(-tiny)), ((-f32::from_bits(1)).to_bits(), -0.0));
        assert_eq!(round_down(1e300), f32::MAX, "beyond the range: the largest float below");
        assert_eq!(round_up(-1e300), f32::MIN);
    }
}
