//! Where a secondary ray starts, and where a shadow ray stops: the one place the integrator decides how
//! far off the surface.
//!
//! Under [`RayOffset::ShadowEpsilon`] (the METU formats) the origin is `p ± ng · ShadowRayEpsilon`, to
//! the side the new ray leaves from, exactly as the official renderers do (the reference images depend
//! on it). Under [`RayOffset::ErrorBound`] (scenes that give no epsilon) it is pbrt-v4's
//! `OffsetRayOrigin`: `p` moved out of its floating-point error box along `ng`
//! ([`crate::geometry::error_bound`]), which avoids both acne and light leaking at any scale.

use crate::geometry::error_bound::offset_ray_origin;
use crate::light::LightSample;
use crate::math::{Ray, Vec3};
use crate::scene::{RayOffset, Surface};

/// The origin of a ray leaving surface `s` towards the side of `side` (the new ray's direction, or any
/// vector on the side it leaves from, relative to the geometric normal), under the scene's `offset`.
#[inline(always)]
pub fn spawn_origin(offset: RayOffset, s: &Surface, side: Vec3) -> Vec3 {
    match offset {
        RayOffset::ShadowEpsilon(epsilon) => s.p + if side.dot(s.ng) > 0.0 { s.ng } else { -s.ng } * epsilon,
        RayOffset::ErrorBound => error_bound_origin(s, side),
    }
}

/// [`offset_ray_origin`] of `s`, out of line, so that [`spawn_origin`] stays small enough to inline
/// into the integrators' loops (the epsilon branch is a few instructions).
#[inline(never)]
fn error_bound_origin(s: &Surface, side: Vec3) -> Vec3 {
    offset_ray_origin(s.p, s.p_error, s.ng, side)
}

/// The shadow ray from `origin` (a [`spawn_origin`] of the shading point `p`) towards the light sample
/// `ls` taken at `p`, and the `t_max` to test it to: the light is blocked when the scene has a hit in
/// `(0, t_max)`. For a light at a finite distance the ray's direction runs from `origin` to the light,
/// so `t = 1` is the light itself.
///
/// Under [`RayOffset::ShadowEpsilon`] the ray reaches `ShadowRayEpsilon` beyond the light: the METU
/// course's renderers count a hit up to and including the light's distance (measured with the shadow
/// epsilon) as blocking, so a surface through a light's position shadows everything on its far side,
/// and a light set into a ceiling leaves the room below dark (project issue 15; no shared reference
/// scene has a light closer than 0.1 to a surface, so no reference image changes with it). Under
/// [`RayOffset::ErrorBound`] it stops at the light, exclusive (pbrt's `SpawnRayTo` stops just short of
/// it). Lights at infinity (directional) are tested to infinity.
///
/// A sampled point on emissive geometry (`on_surface`) is on a surface the scene holds, which must not
/// block its own light: the ray stops short of it, by `ShadowRayEpsilon`, or under
/// [`RayOffset::ErrorBound`] by pbrt's relative `ShadowEpsilon` (1e-4 of the way).
#[inline]
pub fn shadow_ray(offset: RayOffset, origin: Vec3, p: Vec3, ls: &LightSample, on_surface: bool) -> (Ray, f32) {
    if !ls.dist.is_finite() {
        return (Ray::new(origin, ls.wi), f32::INFINITY);
    }
    let to_light = p + ls.wi * ls.dist - origin;
    let t_max = match (offset, on_surface) {
        (RayOffset::ShadowEpsilon(epsilon), false) => 1.0 + epsilon / to_light.length(),
        (RayOffset::ShadowEpsilon(epsilon), true) => 1.0 - epsilon / to_light.length(),
        (RayOffset::ErrorBound, false) => 1.0,
        (RayOffset::ErrorBound, true) => 1.0 - 1e-4,
    };
    (Ray::new(origin, to_light), t_max)
}
