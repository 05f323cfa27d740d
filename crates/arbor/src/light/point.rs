//! Point lights: irradiance `intensity / d²` (the course's definition, no 4π); a delta light, of power
//! `4π I`.

use super::{Light, LightSample};
use crate::math::{Color, Vec2, Vec3};
use crate::tonemap::luminance;

/// Light from a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointLight {
    /// Position.
    pub position: Vec3,
    /// Intensity.
    pub intensity: Color,
}

/// `intensity / d²`, or `None` when `d` is not positive (a surface touches the light).
pub(super) fn inverse_square(intensity: f32, d: f32) -> Option<f32> {
    let bound = intensity / (d * d);
    (d > 0.0 && bound.is_finite()).then_some(bound)
}

impl Light for PointLight {
    fn sample(&self, p: Vec3, _n: Vec3, _u: Vec2) -> Option<LightSample> {
        let to_light = self.position - p;
        let d2 = to_light.length_squared();
        // Negated so that a NaN distance (a NaN point) gives no light, as a zero one does.
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        if !(d2 > 0.0) {
            return None;
        }
        let dist = d2.sqrt();
        Some(LightSample { wi: to_light / dist, dist, irradiance: self.intensity / d2, pdf: 0.0 })
    }

    fn power(&self) -> f32 {
        4.0 * std::f32::consts::PI * luminance(self.intensity)
    }

    /// `I / d²` at the nearest surface.
    fn irradiance_bound(&self, clearance: &dyn Fn(Vec3) -> f32) -> Option<f32> {
        inverse_square(self.intensity.max_element(), clearance(self.position))
    }

    fn is_delta(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn point_light_falls_off_with_square_distance() {
        let light = PointLight { position: Vec3::new(0.0, 2.0, 0.0), intensity: Vec3::splat(100.0) };
        let s = light.sample(Vec3::ZERO, Vec3::Y, Vec2::ZERO).unwrap();
        assert_eq!(s.wi, Vec3::Y);
        assert_eq!(s.dist, 2.0);
        assert_eq!(s.irradiance, Vec3::splat(25.0));
        assert!(PointLight { position: Vec3::ZERO, intensity: Vec3::ONE }
            .sample(Vec3::ZERO, Vec3::Y, Vec2::ZERO)
            .is_none());
    }
}
