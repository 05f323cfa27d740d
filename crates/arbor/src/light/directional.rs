//! Directional lights (CENG 795 hw5): parallel light travelling along `direction`.

use super::LightSample;
use crate::math::{Color, Vec3};

/// The light reaching any point: from `-direction`, unattenuated.
pub fn sample_directional(direction: Vec3, radiance: Color) -> Option<LightSample> {
    let wi = -direction.try_normalize()?;
    Some(LightSample { wi, dist: f32::INFINITY, irradiance: radiance })
}
