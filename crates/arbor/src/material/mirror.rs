//! `type="mirror"`: a perfect reflection weighted by `MirrorReflectance`, without Fresnel.

use super::{Lobe, SpecularLayer};
use crate::math::{reflect, Color, Vec3};

/// A perfect mirror.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mirror {
    /// `MirrorReflectance`.
    pub reflectance: Color,
}

impl Mirror {
    /// The mirror's single lobe.
    pub fn lobe(&self, d: Vec3, n: Vec3) -> Lobe {
        Lobe { dir: reflect(d, n).normalize(), weight: self.reflectance, transmitted: false }
    }
}

impl SpecularLayer for Mirror {
    fn lobes(&self, d: Vec3, n: Vec3) -> Vec<Lobe> {
        vec![self.lobe(d, n)]
    }
    fn weight_bound(&self) -> f32 {
        self.reflectance.max_element()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mirror_reflects_about_the_normal_with_its_reflectance() {
        let m = Mirror { reflectance: Color::new(0.5, 0.25, 1.0) };
        let d = Vec3::new(1.0, -1.0, 0.0).normalize();
        let lobes = m.lobes(d, Vec3::Y);
        assert_eq!(lobes.len(), 1);
        assert!(lobes[0].dir.abs_diff_eq(Vec3::new(1.0, 1.0, 0.0).normalize(), 1e-6));
        assert_eq!(lobes[0].weight, m.reflectance);
        assert!(!lobes[0].transmitted && !m.transmits() && m.interior_absorption().is_none());
    }
}
