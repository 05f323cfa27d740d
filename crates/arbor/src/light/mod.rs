//! Lights at render time: what a shading point receives from each light ([`Light::sample`] gives a
//! [`LightSample`]), and the environment map for rays that miss. The scene's build step makes the lights
//! from the description; nothing here knows the scene file.
//!
//! A new kind of light is a type in its own file implementing [`Light`]; the integrator only asks the
//! trait.

mod area;
mod directional;
pub mod environment;
mod latlong_sampling;
mod point;
mod spherical_directional;
mod spot;

use std::fmt;

use crate::math::{Color, Vec2, Vec3};

pub use area::AreaLight;
pub use directional::DirectionalLight;
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
    /// Irradiance on a surface facing the light, before the cosine term.
    pub irradiance: Color,
}

/// A light source other than the ambient light and the environment.
pub trait Light: fmt::Debug + Send + Sync {
    /// The light reaching point `p` of a surface whose (unit) normal on the lit side is `n`; `u` (in
    /// `[0,1)²`) picks the point on a light with an area, or the direction of an environment. `None` when
    /// nothing arrives (`p` on a point light, a zero direction).
    fn sample(&self, p: Vec3, n: Vec3, u: Vec2) -> Option<LightSample>;
}
