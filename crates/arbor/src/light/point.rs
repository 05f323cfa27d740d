//! Point lights: irradiance `intensity / d²` (the course's definition, no 4π).

use super::LightSample;
use crate::math::{Color, Vec3};

/// The light a point light at `position` gives point `p`; `None` when `p` is at the light.
pub fn sample_point(position: Vec3, intensity: Color, p: Vec3) -> Option<LightSample> {
    let to_light = position - p;
    let d2 = to_light.length_squared();
    if !(d2 > 0.0) {
        return None;
    }
    let dist = d2.sqrt();
    Some(LightSample { wi: to_light / dist, dist, irradiance: intensity / d2 })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn point_light_falls_off_with_square_distance() {
        let s = sample_point(Vec3::new(0.0, 2.0, 0.0), Vec3::splat(100.0), Vec3::ZERO).unwrap();
        assert_eq!(s.wi, Vec3::Y);
        assert_eq!(s.dist, 2.0);
        assert_eq!(s.irradiance, Vec3::splat(25.0));
        assert!(sample_point(Vec3::ZERO, Vec3::ONE, Vec3::ZERO).is_none());
    }
}
