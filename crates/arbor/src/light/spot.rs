//! Spot lights (CENG 795 hw5): a point light whose light leaves in a cone. Inside half the fall-off
//! angle of its axis it is a point light (`I / d²`); between that and half the coverage angle the
//! irradiance is scaled by `s = ((cos α - cos(coverage/2)) / (cos(falloff/2) - cos(coverage/2)))⁴`, which
//! falls smoothly from 1 at the fall-off edge to 0 at the coverage edge; outside the coverage cone no
//! light arrives. (The assignment text prints `cos(falloff/2)` in the numerator, which would make the
//! light brighten towards the coverage edge, against the text's own description of a diminishing light.)
//! A delta light; its power is pbrt-v3's approximation, `2π I (1 - (cos falloff + cos coverage) / 2)`
//! with the half angles.

use super::{Light, LightSample, PointLight};
use crate::math::{Color, Vec2, Vec3};
use crate::tonemap::luminance;

/// A point light emitting in a cone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpotLight {
    /// Position.
    pub position: Vec3,
    /// Unit axis of the cone, pointing away from the light.
    pub axis: Vec3,
    /// Intensity inside the fall-off cone.
    pub intensity: Color,
    /// Cosine of half the coverage angle: no light beyond it.
    pub cos_coverage: f32,
    /// Cosine of half the fall-off angle: full intensity within it.
    pub cos_falloff: f32,
}

impl SpotLight {
    /// A spot light from full cone angles in degrees (`0 < falloff <= coverage <= 360`); `direction`
    /// need not be unit. `None` for a zero direction.
    pub fn new(position: Vec3, direction: Vec3, intensity: Color, coverage_deg: f32, falloff_deg: f32) -> Option<Self> {
        let half_cos = |deg: f32| (deg.to_radians() / 2.0).cos();
        Some(SpotLight {
            position,
            axis: direction.try_normalize()?,
            intensity,
            cos_coverage: half_cos(coverage_deg),
            cos_falloff: half_cos(falloff_deg),
        })
    }

    /// The share of the intensity leaving along the unit direction `d`.
    pub fn attenuation(&self, d: Vec3) -> f32 {
        let cos_a = self.axis.dot(d);
        if cos_a >= self.cos_falloff {
            1.0
        } else if cos_a <= self.cos_coverage {
            0.0
        } else {
            ((cos_a - self.cos_coverage) / (self.cos_falloff - self.cos_coverage)).powi(4)
        }
    }
}

impl Light for SpotLight {
    fn sample(&self, p: Vec3, n: Vec3, u: Vec2) -> Option<LightSample> {
        // A point light whose intensity falls off away from the axis.
        let ls = PointLight { position: self.position, intensity: self.intensity }.sample(p, n, u)?;
        let s = self.attenuation(-ls.wi);
        (s > 0.0).then(|| LightSample { irradiance: ls.irradiance * s, ..ls })
    }

    /// A point light's: the fall-off only dims it.
    fn irradiance_bound(&self, clearance: &dyn Fn(Vec3) -> f32) -> Option<f32> {
        super::point::inverse_square(self.intensity.max_element(), clearance(self.position))
    }

    fn power(&self) -> f32 {
        let cone = 1.0 - 0.5 * (self.cos_falloff + self.cos_coverage);
        std::f32::consts::TAU * luminance(self.intensity) * cone
    }

    fn is_delta(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A light 2 above the origin pointing down, coverage 90° (45° half), fall-off 60° (30° half).
    fn spot() -> SpotLight {
        SpotLight::new(Vec3::new(0.0, 2.0, 0.0), Vec3::new(0.0, -5.0, 0.0), Color::splat(100.0), 90.0, 60.0).unwrap()
    }

    #[test]
    fn spot_light_is_a_point_light_inside_the_falloff_cone() {
        let s = spot().sample(Vec3::ZERO, Vec3::Y, Vec2::ZERO).unwrap();
        assert_eq!((s.wi, s.dist, s.irradiance), (Vec3::Y, 2.0, Color::splat(25.0)));
        // 20° off the axis, still inside the 30° half fall-off angle.
        let x = 2.0 * 20f32.to_radians().tan();
        let s = spot().sample(Vec3::new(x, 0.0, 0.0), Vec3::Y, Vec2::ZERO).unwrap();
        assert!((s.irradiance.x - 100.0 / (4.0 + x * x)).abs() < 1e-4);
    }

    #[test]
    fn spot_light_falls_off_smoothly_to_nothing_beyond_the_coverage_cone() {
        let light = spot();
        let at = |deg: f32| light.attenuation(Vec3::new(deg.to_radians().sin(), -deg.to_radians().cos(), 0.0));
        assert!((at(30.0) - 1.0).abs() < 1e-4 && at(45.0).abs() < 1e-4);
        // 40° by hand: ((cos 40° - cos 45°) / (cos 30° - cos 45°))^4 = (0.058939 / 0.158919)^4 = 0.018920.
        assert!((at(40.0) - 0.018920).abs() < 1e-4, "{}", at(40.0));
        assert!(at(35.0) > at(40.0) && at(35.0) < 1.0);
        assert!(light.sample(Vec3::new(2.1, 0.0, 0.0), Vec3::Y, Vec2::ZERO).is_none(), "46° off the axis: dark");
        assert!(light.sample(Vec3::new(0.0, 3.0, 0.0), Vec3::Y, Vec2::ZERO).is_none(), "behind the light: dark");
    }

    #[test]
    fn spot_light_with_equal_angles_has_a_hard_edge() {
        let light = SpotLight::new(Vec3::ZERO, -Vec3::Y, Color::ONE, 60.0, 60.0).unwrap();
        assert_eq!(light.attenuation(Vec3::new(0.0, -1.0, 0.0)), 1.0);
        assert_eq!(light.attenuation(Vec3::new(1.0, -1.0, 0.0).normalize()), 0.0);
        assert!(SpotLight::new(Vec3::ZERO, Vec3::ZERO, Color::ONE, 60.0, 30.0).is_none());
    }
}
