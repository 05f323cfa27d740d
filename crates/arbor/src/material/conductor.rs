//! `type="conductor"`: metals. The reflection is weighted by the unpolarised Fresnel reflectance of a
//! conductor with complex index `eta + i k`, times `MirrorReflectance` (which gives metals their colour),
//! in the approximation the course uses (the `n² + k²` form, exact at normal incidence).

use super::{Lobe, SpecularLayer};
use crate::math::{reflect, Color, Vec3};

/// Fresnel reflectance of a conductor for the cosine `cos_i` of the incidence angle.
pub fn fresnel_conductor(cos_i: f32, eta: f32, k: f32) -> f32 {
    let c = cos_i.clamp(0.0, 1.0);
    let c2 = c * c;
    let nk = eta * eta + k * k;
    let two_nc = 2.0 * eta * c;
    let rs = (nk - two_nc + c2) / (nk + two_nc + c2);
    let rp = (nk * c2 - two_nc + 1.0) / (nk * c2 + two_nc + 1.0);
    0.5 * (rs + rp)
}

/// A metal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Conductor {
    /// `MirrorReflectance`.
    pub reflectance: Color,
    /// `RefractionIndex` (n).
    pub eta: f32,
    /// `AbsorptionIndex` (k).
    pub k: f32,
}

impl SpecularLayer for Conductor {
    /// The conductor's single reflection lobe.
    fn lobes(&self, d: Vec3, n: Vec3) -> Vec<Lobe> {
        let cos_i = -d.dot(n);
        let fr = fresnel_conductor(cos_i.abs(), self.eta, self.k);
        vec![Lobe { dir: reflect(d, n).normalize(), weight: self.reflectance * fr, transmitted: false }]
    }
    /// Fresnel reflectance is at most 1.
    fn weight_bound(&self) -> f32 {
        self.reflectance.max_element()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conductor_normal_incidence_matches_closed_form() {
        // At normal incidence R = ((n-1)² + k²) / ((n+1)² + k²).
        let (n, k) = (0.37f32, 2.82f32);
        let expected = ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
        assert!((fresnel_conductor(1.0, n, k) - expected).abs() < 1e-6);
    }

    #[test]
    fn conductor_lobe_reflects_with_fresnel_times_reflectance() {
        let m = Conductor { reflectance: Color::new(1.0, 0.5, 0.25), eta: 0.37, k: 2.82 };
        let lobes = m.lobes(-Vec3::Y, Vec3::Y);
        assert_eq!(lobes.len(), 1);
        assert_eq!(lobes[0].dir, Vec3::Y);
        assert_eq!(lobes[0].weight, m.reflectance * fresnel_conductor(1.0, 0.37, 2.82));
        assert!(!m.transmits() && m.interior_absorption().is_none());
    }

    #[test]
    fn conductor_grazing_incidence_reflects_everything() {
        assert!((fresnel_conductor(0.0, 0.37, 2.82) - 1.0).abs() < 1e-6);
    }
}
