//! The renderer's vector vocabulary: the geometry types of [`arbor_accel::math`] (vectors, rays, boxes,
//! transforms), plus what only shading needs (colours, reflection, tangent frames).

pub use arbor_accel::math::*;

/// Linear RGB radiance. Scene files use their own scale; see [`crate::scene::SceneDesc::radiance_scale`].
pub type Color = Vec3;

/// Reflects `d` about the normal `n` (both pointing away from the surface for `n`, `d` incoming).
#[inline]
pub fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - 2.0 * d.dot(n) * n
}

/// An orthonormal basis `(t, b)` perpendicular to the unit vector `n` (Duff et al. 2017, branchless).
#[inline]
pub fn orthonormal_basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), Vec3::new(b, sign + n.y * n.y * a, -n.y))
}
