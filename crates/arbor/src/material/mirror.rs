//! `type="mirror"`: a perfect reflection weighted by `MirrorReflectance`, without Fresnel.

use super::Lobe;
use crate::math::{reflect, Color, Vec3};

/// The mirror's single lobe.
pub fn lobe(reflectance: Color, d: Vec3, n: Vec3) -> Lobe {
    Lobe { dir: reflect(d, n).normalize(), weight: reflectance, transmitted: false }
}
