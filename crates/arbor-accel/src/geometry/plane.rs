//! Infinite planes. They have no bounds, so they live outside the bounded hierarchy and are tested
//! one by one after it.

use crate::math::{Ray, Vec3};

/// The plane through `point` with unit normal `normal`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    /// A point on the plane.
    pub point: Vec3,
    /// Unit normal.
    pub normal: Vec3,
}

impl Plane {
    /// The `t` in `(0, t_max)` where the ray crosses the plane, if any.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        let denom = ray.dir.dot(self.normal);
        if denom == 0.0 || (ray.cull_backfaces && denom > 0.0) {
            return None;
        }
        let t = (self.point - ray.origin).dot(self.normal) / denom;
        (t > 0.0 && t < t_max).then_some(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plane_hit_parallel_and_behind() {
        let p = Plane { point: Vec3::new(0.0, -1.0, 0.0), normal: Vec3::Y };
        let down = Ray::new(Vec3::ZERO, Vec3::new(0.0, -2.0, 0.0));
        assert!((p.intersect(&down, f32::INFINITY).unwrap() - 0.5).abs() < 1e-6);
        assert!(p.intersect(&Ray::new(Vec3::ZERO, Vec3::X), f32::INFINITY).is_none());
        assert!(p.intersect(&Ray::new(Vec3::ZERO, Vec3::Y), f32::INFINITY).is_none());
    }
}
