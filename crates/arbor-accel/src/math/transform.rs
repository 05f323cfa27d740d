//! Affine transforms with their inverse kept, so that normals (inverse transpose) and object-space rays
//! cost no inversion at render time.

use super::{Mat3, Mat4, Vec3};

/// An affine transform and its inverse.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transform {
    /// Object to world.
    pub m: Mat4,
    /// World to object.
    pub inv: Mat4,
}

impl Default for Transform {
    fn default() -> Self {
        Transform::IDENTITY
    }
}

impl Transform {
    /// The identity.
    pub const IDENTITY: Transform = Transform { m: Mat4::IDENTITY, inv: Mat4::IDENTITY };

    /// From a matrix; `None` when it cannot be inverted (a zero scale, say).
    pub fn from_mat4(m: Mat4) -> Option<Self> {
        let det = m.determinant();
        if !det.is_finite() || det.abs() < 1e-30 {
            return None;
        }
        Some(Transform { m, inv: m.inverse() })
    }
    /// A translation.
    pub fn translate(t: Vec3) -> Self {
        Transform { m: Mat4::from_translation(t), inv: Mat4::from_translation(-t) }
    }
    /// A scale; `None` when a factor is zero.
    pub fn scale(s: Vec3) -> Option<Self> {
        Transform::from_mat4(Mat4::from_scale(s))
    }
    /// A counter-clockwise rotation by `deg` degrees about `axis`; `None` for a zero axis.
    pub fn rotate(deg: f32, axis: Vec3) -> Option<Self> {
        let axis = axis.try_normalize()?;
        let m = Mat4::from_axis_angle(axis, deg.to_radians());
        Some(Transform { m, inv: m.transpose() })
    }
    /// `self` applied first, then `then`.
    pub fn then(&self, then: &Transform) -> Transform {
        Transform { m: then.m * self.m, inv: self.inv * then.inv }
    }
    /// True when every entry of the matrix and of its inverse is a finite number; a composition of
    /// large (or small) factors can overflow where none of its parts does.
    pub fn is_finite(&self) -> bool {
        self.m.is_finite() && self.inv.is_finite()
    }
    /// True for the identity (skips work on untransformed objects).
    pub fn is_identity(&self) -> bool {
        self.m == Mat4::IDENTITY
    }
    /// A point, object to world.
    #[inline]
    pub fn point(&self, p: Vec3) -> Vec3 {
        self.m.transform_point3(p)
    }
    /// A direction, object to world.
    #[inline]
    pub fn vector(&self, v: Vec3) -> Vec3 {
        self.m.transform_vector3(v)
    }
    /// A normal, object to world (inverse transpose); not normalised.
    #[inline]
    pub fn normal(&self, n: Vec3) -> Vec3 {
        self.normal_matrix() * n
    }
    /// The matrix that takes normals to world space.
    #[inline]
    pub fn normal_matrix(&self) -> Mat3 {
        Mat3::from_mat4(self.inv).transpose()
    }
    /// True when the transform flips handedness (mirrors), which reverses triangle winding.
    pub fn flips_handedness(&self) -> bool {
        Mat3::from_mat4(self.m).determinant() < 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transform_then_applies_first_operand_first() {
        let t = Transform::translate(Vec3::X);
        let s = Transform::scale(Vec3::splat(2.0)).unwrap();
        let ts = t.then(&s);
        assert!((ts.point(Vec3::ZERO) - Vec3::new(2.0, 0.0, 0.0)).length() < 1e-6);
        assert!((ts.inv.transform_point3(Vec3::new(2.0, 0.0, 0.0))).length() < 1e-6);
    }

    #[test]
    fn transform_normal_stays_perpendicular_under_nonuniform_scale() {
        let s = Transform::scale(Vec3::new(4.0, 1.0, 1.0)).unwrap();
        let tangent = s.vector(Vec3::new(1.0, 1.0, 0.0));
        let n = s.normal(Vec3::new(1.0, -1.0, 0.0));
        assert!(tangent.dot(n).abs() < 1e-5);
    }

    #[test]
    fn transform_composition_can_overflow_where_its_parts_do_not() {
        let big = Transform::scale(Vec3::new(1e20, 1.0, 1.0)).unwrap();
        let small = Transform::scale(Vec3::new(1e-20, 1.0, 1.0)).unwrap();
        assert!(big.is_finite() && small.is_finite() && big.then(&small).is_finite());
        assert!(!big.then(&big).is_finite(), "the matrix overflows");
        assert!(!small.then(&small).is_finite(), "the inverse overflows");
    }

    #[test]
    fn transform_rotation_is_counter_clockwise() {
        let r = Transform::rotate(90.0, Vec3::Z).unwrap();
        assert!((r.vector(Vec3::X) - Vec3::Y).length() < 1e-6);
    }
}
