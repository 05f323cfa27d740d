//! `type="dielectric"`: glass. Snell's law, the unpolarised Fresnel reflectance, total internal
//! reflection, and Beer's law for the light travelling inside (applied by the integrator along each
//! segment, since only it knows the distance).

use super::{Lobe, SpecularLayer};
use crate::math::{reflect, Color, Vec3};

/// Fresnel reflectance for light going from index `eta_i` into `eta_t` with incidence cosine `cos_i`
/// (> 0); 1 under total internal reflection.
pub fn fresnel_dielectric(cos_i: f32, eta_i: f32, eta_t: f32) -> f32 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin_t = eta_i / eta_t * (1.0 - cos_i * cos_i).max(0.0).sqrt();
    if sin_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin_t * sin_t).max(0.0).sqrt();
    let r_par = (eta_t * cos_i - eta_i * cos_t) / (eta_t * cos_i + eta_i * cos_t);
    let r_perp = (eta_i * cos_i - eta_t * cos_t) / (eta_i * cos_i + eta_t * cos_t);
    0.5 * (r_par * r_par + r_perp * r_perp)
}

/// The refracted unit direction of unit `d` through a surface with unit normal `n` facing the incoming
/// side, for index ratio `eta = eta_i / eta_t`; `None` under total internal reflection.
pub fn refract(d: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = -d.dot(n);
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    if k < 0.0 {
        return None;
    }
    Some((eta * d + (eta * cos_i - k.sqrt()) * n).normalize())
}

/// Glass with Beer's law inside.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dielectric {
    /// `RefractionIndex`.
    pub eta: f32,
    /// `AbsorptionCoefficient`, per channel, per unit distance.
    pub absorption: Color,
}

impl SpecularLayer for Dielectric {
    fn lobes(&self, d: Vec3, n: Vec3) -> Vec<Lobe> {
        lobes(self.eta, Color::ONE, d, n)
    }
    fn max_lobes(&self) -> usize {
        2
    }
    /// `F + (1 - F)`: what is not reflected is refracted.
    fn weight_bound(&self) -> f32 {
        1.0
    }
    fn transmits(&self) -> bool {
        true
    }
    fn interior_absorption(&self) -> Option<Color> {
        Some(self.absorption)
    }
}

/// Beer's law: the fraction of light left after `distance` in a medium absorbing `absorption` per unit.
#[inline]
pub fn beer(absorption: Color, distance: f32) -> Color {
    (-absorption * distance).exp()
}

/// Reflection (weight F) and refraction (weight `(1 - F) * transmit`) at a surface of index `eta` with
/// outward normal `n`, entered from whichever side `d` comes.
pub(super) fn lobes(eta: f32, transmit: Color, d: Vec3, n: Vec3) -> Vec<Lobe> {
    let entering = d.dot(n) < 0.0;
    let (facing, eta_i, eta_t) = if entering { (n, 1.0, eta) } else { (-n, eta, 1.0) };
    let cos_i = -d.dot(facing);
    let reflected = reflect(d, facing).normalize();
    match refract(d, facing, eta_i / eta_t) {
        None => vec![Lobe { dir: reflected, weight: Color::ONE, transmitted: false }],
        Some(t) => {
            let f = fresnel_dielectric(cos_i, eta_i, eta_t);
            vec![
                Lobe { dir: reflected, weight: Color::splat(f), transmitted: false },
                Lobe { dir: t, weight: transmit * (1.0 - f), transmitted: true },
            ]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dielectric_normal_incidence_matches_closed_form() {
        let r = fresnel_dielectric(1.0, 1.0, 1.5);
        assert!((r - 0.04).abs() < 1e-6);
    }

    #[test]
    fn dielectric_snell_law_holds() {
        let d = Vec3::new(0.6, -0.8, 0.0);
        let t = refract(d, Vec3::Y, 1.0 / 1.5).unwrap();
        assert!((t.x - 0.6 / 1.5).abs() < 1e-6);
        assert!(t.y < 0.0);
    }

    #[test]
    fn dielectric_total_internal_reflection_beyond_critical_angle() {
        // Inside glass (eta 1.5) at 60 degrees from the normal: sin 60 * 1.5 > 1.
        let d = Vec3::new(60f32.to_radians().sin(), 60f32.to_radians().cos(), 0.0);
        let lobes = lobes(1.5, Color::ONE, d, Vec3::Y);
        assert_eq!(lobes.len(), 1);
        assert_eq!(lobes[0].weight, Color::ONE);
        assert!(!lobes[0].transmitted);
        assert!(lobes[0].dir.y < 0.0, "reflected back inside");
    }

    #[test]
    fn dielectric_lobes_conserve_energy() {
        let d = Vec3::new(0.3, -1.0, 0.2).normalize();
        let l = lobes(1.55, Color::ONE, d, Vec3::Y);
        assert!((l[0].weight.x + l[1].weight.x - 1.0).abs() < 1e-6);
    }

    #[test]
    fn dielectric_layer_transmits_into_its_absorbing_medium() {
        let glass = Dielectric { eta: 1.5, absorption: Color::new(0.1, 0.2, 0.3) };
        assert!(glass.transmits());
        assert_eq!(glass.interior_absorption(), Some(Color::new(0.1, 0.2, 0.3)));
        let d = Vec3::new(0.3, -1.0, 0.2).normalize();
        assert_eq!(glass.lobes(d, Vec3::Y), lobes(1.5, Color::ONE, d, Vec3::Y));
    }

    #[test]
    fn dielectric_beer_attenuates_exponentially() {
        let a = beer(Color::new(0.0, 0.5, 1.0), 2.0);
        assert!(a.abs_diff_eq(Color::new(1.0, (-1.0f32).exp(), (-2.0f32).exp()), 1e-6));
    }
}
