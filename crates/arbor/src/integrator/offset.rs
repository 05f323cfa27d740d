//! Where a secondary ray starts: the one place the integrator decides how far off the surface.
//!
//! Under [`RayOffset::ShadowEpsilon`] (the METU formats) the origin is `p ± ng · ShadowRayEpsilon`, to
//! the side the new ray leaves from, exactly as the official renderers do (the reference images depend
//! on it). Under [`RayOffset::ErrorBound`] (scenes that give no epsilon) it is pbrt-v4's
//! `OffsetRayOrigin`: `p` moved out of its floating-point error box along `ng`
//! ([`crate::geometry::error_bound`]), which avoids both acne and light leaking at any scale.

use crate::geometry::error_bound::offset_ray_origin;
use crate::math::Vec3;
use crate::scene::{RayOffset, Surface};

/// The origin of a ray leaving surface `s` towards the side of `side` (the new ray's direction, or any
/// vector on the side it leaves from, relative to the geometric normal), under the scene's `offset`.
#[inline]
pub fn spawn_origin(offset: RayOffset, s: &Surface, side: Vec3) -> Vec3 {
    match offset {
        RayOffset::ShadowEpsilon(epsilon) => s.p + if side.dot(s.ng) > 0.0 { s.ng } else { -s.ng } * epsilon,
        RayOffset::ErrorBound => offset_ray_origin(s.p, s.p_error, s.ng, side),
    }
}
