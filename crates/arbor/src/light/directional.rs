//! Directional lights (CENG 795 hw5): parallel light travelling along `direction`; a delta light. Its
//! power is what crosses the disc of the scene's bounding sphere, `π r² E` (pbrt).

use super::{Light, LightSample};
use crate::math::{Color, Vec2, Vec3};
use crate::tonemap::luminance;

/// Parallel light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DirectionalLight {
    /// Direction of travel (need not be unit).
    pub direction: Vec3,
    /// Irradiance on a surface facing it.
    pub radiance: Color,
    /// Radius of the scene's bounding sphere (for [`Light::power`] only).
    pub scene_radius: f32,
}

impl Light for DirectionalLight {
    /// The light reaching any point: from `-direction`, unattenuated, from infinitely far.
    fn sample(&self, _p: Vec3, _n: Vec3, _u: Vec2) -> Option<LightSample> {
        let wi = -self.direction.try_normalize()?;
        Some(LightSample { wi, dist: f32::INFINITY, irradiance: self.radiance, pdf: 0.0 })
    }

    fn irradiance_bound(&self, _clearance: &dyn Fn(Vec3) -> f32) -> Option<f32> {
        Some(self.radiance.max_element())
    }

    fn power(&self) -> f32 {
        std::f32::consts::PI * self.scene_radius * self.scene_radius * luminance(self.radiance)
    }

    fn is_delta(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directional_light_comes_from_against_its_direction() {
        let light =
            DirectionalLight { direction: Vec3::new(0.0, -2.0, 0.0), radiance: Color::splat(3.0), scene_radius: 1.0 };
        let s = light.sample(Vec3::new(5.0, 1.0, -2.0), Vec3::Y, Vec2::ZERO).unwrap();
        assert_eq!(s, LightSample { wi: Vec3::Y, dist: f32::INFINITY, irradiance: Color::splat(3.0), pdf: 0.0 });
        assert!(DirectionalLight { direction: Vec3::ZERO, radiance: Color::ONE, scene_radius: 1.0 }
            .sample(Vec3::ZERO, Vec3::Y, Vec2::ZERO)
            .is_none());
    }
}
