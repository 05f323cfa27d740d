//! Spheres, optionally under an affine transform (a non-uniform scale makes an ellipsoid): the ray is
//! taken to object space, where the sphere is `|p - center| = radius`.

use crate::math::{Aabb, Ray, Transform, Vec3};

/// A sphere in object space and the transform that places it in the world.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    /// Centre, object space.
    pub center: Vec3,
    /// Radius (> 0).
    pub radius: f32,
    /// Object to world.
    pub transform: Transform,
}

impl Sphere {
    /// World-space bounds (the transformed object-space box: conservative for rotations).
    pub fn bounds(&self) -> Aabb {
        let r = Vec3::splat(self.radius);
        let (lo, hi) = (self.center - r, self.center + r);
        if self.transform.is_identity() {
            return Aabb::new(lo, hi);
        }
        let mut b = Aabb::EMPTY;
        for i in 0..8 {
            let corner = Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            b = b.grow(self.transform.point(corner));
        }
        b
    }

    /// The nearest `t` in `(0, t_max)` where the ray meets the sphere.
    ///
    /// The discriminant is computed as `r² - |f - (f·d̂)d̂|²` (Haines et al., Ray Tracing Gems ch. 7),
    /// which keeps its precision for small spheres far from the ray origin.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        let (o, d) = if self.transform.is_identity() {
            (ray.origin, ray.dir)
        } else {
            (self.transform.inv.transform_point3(ray.origin), self.transform.inv.transform_vector3(ray.dir))
        };
        let dd = d.length_squared();
        let f = o - self.center;
        let b = -f.dot(d);
        let l = f + (b / dd) * d;
        let disc = dd * (self.radius * self.radius - l.length_squared());
        // Negated so that a NaN discriminant (a degenerate ray or sphere) is a miss too.
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        if !(disc >= 0.0) {
            return None;
        }
        // The two roots are q/|d|² and c/q; computing one from the other avoids cancellation.
        let q = b + disc.sqrt().copysign(b);
        let c = f.length_squared() - self.radius * self.radius;
        let (r0, r1) = if q == 0.0 { (0.0, 0.0) } else { (q / dd, c / q) };
        let (t0, t1) = if r0 <= r1 { (r0, r1) } else { (r1, r0) };
        [t0, t1].into_iter().find(|&t| t > 0.0 && t < t_max)
    }

    /// The unit outward normal, world space, at world point `p` on the surface.
    pub fn normal_at(&self, p: Vec3) -> Vec3 {
        if self.transform.is_identity() {
            return ((p - self.center) / self.radius).normalize();
        }
        let po = self.transform.inv.transform_point3(p);
        self.transform.normal(po - self.center).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit() -> Sphere {
        Sphere { center: Vec3::ZERO, radius: 1.0, transform: Transform::IDENTITY }
    }

    #[test]
    fn sphere_hit_from_outside_and_inside() {
        let s = unit();
        let t = s.intersect(&Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::new(0.0, 0.0, -1.0)), f32::INFINITY);
        assert!((t.unwrap() - 4.0).abs() < 1e-6);
        let t = s.intersect(&Ray::new(Vec3::ZERO, Vec3::new(0.0, 0.0, -2.0)), f32::INFINITY);
        assert!((t.unwrap() - 0.5).abs() < 1e-6);
        assert!(s.intersect(&Ray::new(Vec3::new(0.0, 2.0, 5.0), Vec3::new(0.0, 0.0, -1.0)), f32::INFINITY).is_none());
        assert!(s.intersect(&Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::new(0.0, 0.0, 1.0)), f32::INFINITY).is_none());
    }

    #[test]
    fn sphere_scaled_into_ellipsoid() {
        let s = Sphere { transform: Transform::scale(Vec3::new(3.0, 1.0, 1.0)).unwrap(), ..unit() };
        let ray = Ray::new(Vec3::new(10.0, 0.0, 0.0), Vec3::new(-1.0, 0.0, 0.0));
        assert!((s.intersect(&ray, f32::INFINITY).unwrap() - 7.0).abs() < 1e-5);
        assert!(s.normal_at(Vec3::new(3.0, 0.0, 0.0)).abs_diff_eq(Vec3::X, 1e-6));
        assert!(s.bounds().max.abs_diff_eq(Vec3::new(3.0, 1.0, 1.0), 1e-6));
    }
}
