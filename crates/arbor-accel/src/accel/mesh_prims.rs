//! A [`TriangleMesh`] as a set of [`Primitives`]: primitive `i` is triangle `i`, intersected with the
//! watertight test ([`intersect_triangle`]), so every structure over a mesh agrees with brute force on
//! shared edges and vertices.
//!
//! A triangle's closest point is Ericson's ([`triangle_point`]), clamped into the triangle's bounds.
//!
//! Bounds are the box of the three corners. A corner with a NaN coordinate drops out of that box (the
//! `min`/`max` of a NaN keeps the other operand), which is harmless: such a triangle is never hit.

use super::{PrimHit, PrimPoint, Primitives};
use crate::geometry::{
    clip_triangle_bounds, closest_point_on_triangle_f64, intersect_triangle, triangle_overlaps_box, TriangleMesh,
};
use crate::math::{Aabb, DVec3, Ray, Vec3};

/// The point of triangle `[a, b, c]` closest to `p`, or `None` for a triangle with a non-finite
/// corner. The one function behind every structure's closest-point query over a mesh, whether the
/// corners come from the mesh or from a BVH leaf's copy of them (the same values), so that all of them
/// weigh the same numbers.
#[inline]
pub(crate) fn triangle_point(p: DVec3, [a, b, c]: [Vec3; 3]) -> Option<PrimPoint> {
    if !(a.is_finite() && b.is_finite() && c.is_finite()) {
        return None;
    }
    let (point, u, v) = closest_point_on_triangle_f64(p, a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
    Some(PrimPoint { point, u, v })
}

impl Primitives for TriangleMesh {
    #[inline]
    fn len(&self) -> usize {
        TriangleMesh::len(self)
    }

    #[inline]
    fn bounds(&self, i: usize) -> Aabb {
        let [a, b, c] = self.triangle(i);
        Aabb::point(a).grow(b).grow(c)
    }

    #[inline]
    fn intersect(&self, i: usize, ray: &Ray, t_max: f32) -> Option<PrimHit> {
        let [a, b, c] = self.triangle(i);
        intersect_triangle(ray, a, b, c, t_max).map(|h| PrimHit::new(h.t, h.b1, h.b2))
    }

    fn overlaps_box(&self, i: usize, b: &Aabb) -> bool {
        let [p, q, r] = self.triangle(i);
        triangle_overlaps_box(p, q, r, b)
    }

    fn clipped_bounds(&self, i: usize, b: &Aabb) -> Aabb {
        let [p, q, r] = self.triangle(i);
        clip_triangle_bounds(p, q, r, b)
    }

    fn closest_point(&self, i: usize, p: DVec3) -> Option<PrimPoint> {
        triangle_point(p, self.triangle(i))
    }

    fn has_closest_point(&self) -> bool {
        true
    }

    fn triangle_mesh(&self) -> Option<&TriangleMesh> {
        Some(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;

    #[test]
    fn mesh_prims_bounds_and_hit_match_the_triangle() {
        let mesh = TriangleMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            indices: vec![[0, 1, 2]],
            ..Default::default()
        };
        assert_eq!(Primitives::len(&mesh), 1);
        assert_eq!(Primitives::bounds(&mesh, 0), Aabb::new(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0)));
        let ray = Ray::new(Vec3::new(0.25, 0.25, 2.0), Vec3::new(0.0, 0.0, -1.0));
        let h = Primitives::intersect(&mesh, 0, &ray, f32::INFINITY).unwrap();
        assert_eq!(h.t, 2.0);
        assert!((h.u - 0.25).abs() < 1e-6 && (h.v - 0.25).abs() < 1e-6);
    }
}
