//! Blinn-Phong, as the courses define it: `k_d max(0, n·l) + k_s max(0, n·h)^p`, times the irradiance.

use super::Material;
use crate::math::{Color, Vec3};

/// The reflected fraction of light arriving from unit `wi` seen from unit `wo`, at shading normal `n`.
#[inline]
pub fn blinn_phong(m: &Material, n: Vec3, wi: Vec3, wo: Vec3) -> Color {
    let cos = n.dot(wi);
    if cos <= 0.0 {
        return Color::ZERO;
    }
    let mut f = m.diffuse * cos;
    if m.specular != Color::ZERO {
        let h = (wi + wo).normalize_or_zero();
        f += m.specular * n.dot(h).max(0.0).powf(m.phong_exponent);
    }
    f
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mat() -> Material {
        Material {
            ambient: Color::ZERO,
            diffuse: Color::splat(0.5),
            specular: Color::splat(0.25),
            phong_exponent: 10.0,
            brdf: None,
            roughness: 0.0,
            layer: None,
            degamma: false,
        }
    }

    #[test]
    fn blinn_phong_head_on_is_diffuse_plus_full_specular() {
        let f = blinn_phong(&mat(), Vec3::Z, Vec3::Z, Vec3::Z);
        assert!(f.abs_diff_eq(Color::splat(0.75), 1e-6));
    }

    #[test]
    fn blinn_phong_light_behind_surface_gives_nothing() {
        assert_eq!(blinn_phong(&mat(), Vec3::Z, -Vec3::Z, Vec3::Z), Color::ZERO);
    }

    #[test]
    fn blinn_phong_diffuse_follows_cosine() {
        let wi = Vec3::new(1.0, 0.0, 1.0).normalize();
        let mut m = mat();
        m.specular = Color::ZERO;
        let f = blinn_phong(&m, Vec3::Z, wi, Vec3::Z);
        assert!((f.x - 0.5 * std::f32::consts::FRAC_1_SQRT_2).abs() < 1e-6);
    }
}
