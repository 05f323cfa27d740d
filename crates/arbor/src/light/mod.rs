//! Lights at render time: what a shading point receives from each light ([`Light::sample`] gives a
//! [`LightSample`]), and the environment map for rays that miss. The scene's build step makes the lights
//! from the description; nothing here knows the scene file.
//!
//! A new kind of light is a type in its own file implementing [`Light`]; the integrator only asks the
//! trait.
//!
//! Densities are per unit solid angle at the receiving point. Lights that are a single point or
//! direction (point, spot, directional) and the hw2 square [`AreaLight`] (not geometry: no ray can hit
//! it) are delta lights: their samples carry `pdf == 0.0` and [`Light::pdf`] is 0 everywhere. For the
//! others (environment, emissive objects) `irradiance == radiance · |cos θ_l| / pdf` expressed per solid
//! angle, i.e. radiance over the sample's solid-angle density, and `pdf` is exactly what [`Light::pdf`]
//! gives the same direction, so a path tracer can weigh light and BRDF samples against each other.

mod area;
mod directional;
mod emissive_mesh;
mod emissive_sphere;
pub mod environment;
mod latlong_sampling;
mod point;
mod spherical_directional;
mod spot;

use std::fmt;

use crate::math::{Color, Vec2, Vec3};

pub use area::AreaLight;
pub use directional::DirectionalLight;
pub use emissive_mesh::{EmissiveMesh, EmitterMesh};
pub use emissive_sphere::EmissiveSphere;
pub use point::PointLight;
pub use spherical_directional::SphericalDirectionalLight;
pub use spot::SpotLight;

/// Light arriving at a point from one light (or one point on an area light).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSample {
    /// Unit direction from the shading point towards the light.
    pub wi: Vec3,
    /// Distance to the light along `wi` (infinite for directional lights); shadow rays stop there.
    pub dist: f32,
    /// Irradiance on a surface facing the light, before the cosine term: a Monte Carlo estimate
    /// (radiance over `pdf` for lights with a density).
    pub irradiance: Color,
    /// The solid-angle density with which `wi` was chosen; 0.0 for a delta light.
    pub pdf: f32,
}

/// A light source other than the ambient light and the environment.
pub trait Light: fmt::Debug + Send + Sync {
    /// The light reaching point `p` of a surface whose (unit) normal on the lit side is `n`; `u` (in
    /// `[0,1)²`) picks the point on a light with an area, or the direction of an environment. `None` when
    /// nothing arrives (`p` on a point light, a zero direction).
    fn sample(&self, p: Vec3, n: Vec3, u: Vec2) -> Option<LightSample>;

    /// The solid-angle density with which [`Light::sample`] at `p` gives the unit direction `wi` (0 for
    /// a delta light, and for a direction that misses the light).
    fn pdf(&self, _p: Vec3, _wi: Vec3) -> f32 {
        0.0
    }

    /// Total emitted power as a luminance, for choosing one light in proportion to its power; each
    /// kind documents its formula.
    fn power(&self) -> f32;

    /// The scene object (index in scene-file order) this light is the emission of, if it is one.
    fn object(&self) -> Option<u32> {
        None
    }

    /// An upper bound on every channel of [`Light::sample`]'s irradiance at any point of the scene,
    /// given `clearance(q)`, a lower bound on the distance from `q` to any surface; `None` when there is
    /// none (a light that surfaces may touch, or whose bound is not worked out).
    fn irradiance_bound(&self, _clearance: &dyn Fn(Vec3) -> f32) -> Option<f32> {
        None
    }

    /// Whether the light is a point or a direction, whose [`Light::sample`] does not read `u`.
    fn is_delta(&self) -> bool {
        false
    }
}

/// A point `q` of a light's surface, of unit normal `n`, chosen with density `area_pdf` per unit area,
/// seen from `p`: the unit direction and distance to it and the density per unit solid angle,
/// `area_pdf · d² / cos θ_l`; `None` when `q` faces away from `p` or coincides with it.
fn towards_area_point(p: Vec3, q: Vec3, n: Vec3, area_pdf: f32) -> Option<(Vec3, f32, f32)> {
    let to = q - p;
    let d2 = to.length_squared();
    let dist = d2.sqrt();
    let wi = to / dist;
    let cos_l = -n.dot(wi);
    // Negated so that a NaN (a zero distance, a degenerate triangle) gives no sample.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    if !(cos_l > 0.0 && d2 > 0.0) {
        return None;
    }
    Some((wi, dist, area_pdf * d2 / cos_l))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn light_is_delta_exactly_when_its_sample_ignores_the_random_numbers() {
        let p = Vec3::new(0.0, 2.0, 0.0);
        let lights: Vec<Box<dyn Light>> = vec![
            Box::new(PointLight { position: Vec3::new(0.0, 5.0, 0.0), intensity: Color::ONE }),
            Box::new(SpotLight::new(Vec3::new(0.0, 5.0, 0.0), -Vec3::Y, Color::ONE, 90.0, 60.0).unwrap()),
            Box::new(DirectionalLight { direction: -Vec3::Y, radiance: Color::ONE, scene_radius: 1.0 }),
            Box::new(AreaLight {
                position: Vec3::new(0.0, 5.0, 0.0),
                normal: -Vec3::Y,
                size: 2.0,
                radiance: Color::ONE,
            }),
        ];
        for light in &lights {
            let at = |u: Vec2| light.sample(p, Vec3::Y, u).map(|s| s.wi);
            let same = at(Vec2::new(0.1, 0.2)) == at(Vec2::new(0.8, 0.7));
            assert!(at(Vec2::new(0.1, 0.2)).is_some(), "{light:?} lights the point");
            assert_eq!(light.is_delta(), same, "{light:?}");
        }
    }
}
