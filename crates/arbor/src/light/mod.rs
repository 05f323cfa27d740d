//! Lights: what a shading point receives from each light ([`LightSample`]), and the environment map for
//! rays that miss.

mod area;
mod directional;
pub mod environment;
mod point;

use crate::math::{Color, Vec2, Vec3};
use crate::scene::LightDesc;

pub use area::sample_area;
pub use directional::sample_directional;
pub use point::sample_point;

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

/// The light from `light` at point `p`; `u` picks the point on an area light.
pub fn sample_light(light: &LightDesc, p: Vec3, u: Vec2) -> Option<LightSample> {
    match *light {
        LightDesc::Point { position, intensity } => sample_point(position, intensity, p),
        LightDesc::Area { position, normal, size, radiance } => sample_area(position, normal, size, radiance, p, u),
        LightDesc::Directional { direction, radiance } => sample_directional(direction, radiance),
    }
}
