//! A ray with the reciprocal direction cached for slab tests.

use super::Vec3;

/// A half-line `origin + t * dir`, `t > 0`, at one instant of the shutter interval. `dir` need not be unit
/// length (t is then in units of `dir`).
#[derive(Debug, Clone, Copy)]
pub struct Ray {
    /// Start point.
    pub origin: Vec3,
    /// Direction.
    pub dir: Vec3,
    /// `1 / dir` per component (infinite for zero components), for box tests.
    pub inv_dir: Vec3,
    /// When in the shutter interval `[0, 1)` the ray sees the scene (motion blur). The structures never
    /// read it; primitives that move take the ray to where they are at this time.
    pub time: f32,
    /// Skip triangles seen from behind (primary rays only, when asked for).
    pub cull_backfaces: bool,
}

impl Ray {
    /// A ray that sees both sides of triangles.
    ///
    /// Subnormal direction components are flushed to zero (keeping their sign): the reciprocal of one
    /// below `1 / f32::MAX` overflows to infinity, and a slab test that multiplies by it would then put
    /// a box met at a finite `t` at infinity and miss hits that brute force finds (found by fuzzing).
    /// The change moves the ray by less than any representable distance relative to its other
    /// components, and every structure, brute force included, sees the same flushed ray.
    #[inline]
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        let tiny = dir.abs().cmplt(Vec3::splat(f32::MIN_POSITIVE));
        let dir = Vec3::select(tiny, dir * 0.0, dir);
        Ray { origin, dir, inv_dir: dir.recip(), time: 0.0, cull_backfaces: false }
    }
    /// The same ray, culling back faces or not.
    #[inline]
    pub fn with_culling(mut self, cull: bool) -> Self {
        self.cull_backfaces = cull;
        self
    }
    /// The same ray at shutter time `time`.
    #[inline]
    pub fn with_time(mut self, time: f32) -> Self {
        self.time = time;
        self
    }
    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + t * self.dir
    }
    /// True when origin and direction are finite and the direction is not zero: others hit nothing.
    #[inline]
    pub fn is_valid(&self) -> bool {
        self.origin.is_finite() && self.dir.is_finite() && self.dir != Vec3::ZERO
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ray_is_valid_only_when_finite_with_a_direction() {
        let (o, d) = (Vec3::new(1.0, -2.0, 3.0), Vec3::new(0.0, 0.5, -1.0));
        assert!(Ray::new(o, d).is_valid());
        assert!(Ray::new(Vec3::splat(f32::MAX), Vec3::splat(-f32::MAX)).is_valid());
        assert!(!Ray::new(o, Vec3::ZERO).is_valid());
        assert!(!Ray::new(o, Vec3::splat(-0.0)).is_valid());
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            for axis in 0..3 {
                let mut v = o.to_array();
                v[axis] = bad;
                assert!(!Ray::new(Vec3::from_array(v), d).is_valid(), "origin {v:?}");
                let mut v = d.to_array();
                v[axis] = bad;
                assert!(!Ray::new(o, Vec3::from_array(v)).is_valid(), "direction {v:?}");
            }
        }
    }
}
