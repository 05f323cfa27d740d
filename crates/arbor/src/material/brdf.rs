//! The course's BRDF models (CENG 795 hw6 `<BRDFs>`): Phong and Blinn-Phong in their original form
//! (Phong 1975; Blinn 1977: the specular lobe divided by the incidence cosine, so the shaded value is the
//! classic `k_d cos θ_i + k_s cos^p`), their modified form (the lobe alone, reciprocal; Lewis 1994),
//! each modified one optionally normalized to conserve energy (`(p+2)/2π` for Phong, the approximation
//! `(p+8)/8π` for Blinn-Phong, Akenine-Möller et al., *Real-Time Rendering*), and Torrance-Sparrow
//! (Cook & Torrance 1982: a Blinn distribution with the exponent, the V-cavity shadowing term, Fresnel).
//!
//! [`Brdf::f`] is the BRDF itself, pbrt's `BxDF::f(wo, wi)`: the integrator multiplies it by the light's
//! irradiance and the incidence cosine. The reflectances are arguments because textures change them per
//! hit. Invariants: `f` is zero for light from below the surface (`n·wi <= 0`) and finite everywhere
//! else; it is symmetric in `wi` and `wo` for the modified models, and for Torrance-Sparrow but for its
//! Fresnel factor, which the course takes at the incidence angle. The normalized models and
//! Torrance-Sparrow reflect at most what they receive, but for the `(p+8)/8π` approximation, which
//! overshoots by up to 7.5% near normal incidence. Cost: one `powf` per evaluation.

use std::f32::consts::PI;

use super::conductor::fresnel_conductor;
use crate::math::{reflect, Color, Vec3};

/// Which of the course's models a [`Brdf`] is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BrdfModel {
    /// `k_d + k_s cos^p α / cos θ_i`, α between the mirror direction of `wi` and `wo`.
    OriginalPhong,
    /// `k_d + k_s cos^p α`; normalized: `k_d / π + k_s (p+2)/2π cos^p α`.
    ModifiedPhong {
        /// Scale the terms so that no light is created.
        normalized: bool,
    },
    /// `k_d + k_s cos^p α_h / cos θ_i`, α_h between the normal and the half vector: the shading every
    /// material without a BRDF gets.
    OriginalBlinnPhong,
    /// `k_d + k_s cos^p α_h`; normalized: `k_d / π + k_s (p+8)/8π cos^p α_h`.
    ModifiedBlinnPhong {
        /// Scale the terms so that (nearly) no light is created.
        normalized: bool,
    },
    /// `k_d / π + k_s D F G / (4 cos θ_i cos θ_o)` with `D = (p+2)/2π cos^p α_h`, `G` the
    /// Cook-Torrance masking term and `F` the course's conductor Fresnel reflectance
    /// ([`super::fresnel_conductor`]) at the incidence angle θ_i.
    TorranceSparrow {
        /// Refraction index n of the Fresnel term.
        eta: f32,
        /// Absorption index k of the Fresnel term (0 for a dielectric).
        k: f32,
        /// The diffuse term is `(1 - F) k_d / π` (light reflected at the surface is not diffused).
        kd_fresnel: bool,
    },
}

/// A BRDF model with its exponent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Brdf {
    /// The model.
    pub model: BrdfModel,
    /// The exponent p of the specular lobe (of the microfacet distribution for Torrance-Sparrow).
    pub exponent: f32,
}

impl Brdf {
    /// The BRDF for light arriving from unit `wi` and leaving towards unit `wo` at unit normal `n`, for
    /// diffuse and specular reflectances `kd` and `ks`.
    pub fn f(&self, kd: Color, ks: Color, wi: Vec3, wo: Vec3, n: Vec3) -> Color {
        let cos_i = n.dot(wi);
        if cos_i <= 0.0 {
            return Color::ZERO;
        }
        // A material without a specular colour skips its lobe's power (most of a diffuse surface's
        // cost); the diffuse term is the same either way.
        self.constant(kd, ks).unwrap_or_else(|| self.formula(kd, ks, wi, wo, n, cos_i))
    }

    /// [`Brdf::f`] by the model's formula, its specular lobe included even when `ks` is black, for
    /// `cos_i = n·wi > 0`.
    fn formula(&self, kd: Color, ks: Color, wi: Vec3, wo: Vec3, n: Vec3, cos_i: f32) -> Color {
        let p = self.exponent;
        match self.model {
            BrdfModel::OriginalPhong => kd + ks * (phong_lobe(wi, wo, n, p) / cos_i),
            BrdfModel::ModifiedPhong { normalized: false } => kd + ks * phong_lobe(wi, wo, n, p),
            BrdfModel::ModifiedPhong { normalized: true } => {
                kd / PI + ks * ((p + 2.0) / (2.0 * PI) * phong_lobe(wi, wo, n, p))
            }
            BrdfModel::OriginalBlinnPhong => kd + ks * (blinn_lobe(wi, wo, n, p) / cos_i),
            BrdfModel::ModifiedBlinnPhong { normalized: false } => kd + ks * blinn_lobe(wi, wo, n, p),
            BrdfModel::ModifiedBlinnPhong { normalized: true } => {
                kd / PI + ks * ((p + 8.0) / (8.0 * PI) * blinn_lobe(wi, wo, n, p))
            }
            BrdfModel::TorranceSparrow { eta, k, kd_fresnel } => {
                // The course's Fresnel term is taken at the incidence angle θ_i (the official images
                // agree to one level; at the half-vector angle they do not), which makes this model
                // not quite reciprocal.
                let fr = fresnel_conductor(cos_i, eta, k);
                let diffuse = if kd_fresnel { kd * ((1.0 - fr) / PI) } else { kd / PI };
                diffuse + ks * (fr * microfacet(wi, wo, n, p))
            }
        }
    }
}

impl Brdf {
    /// [`Brdf::f`] for light from above the surface (`n·wi > 0`) when it depends on neither direction
    /// (a model's diffuse term alone, its specular colour black): the same value `f` gives, computed
    /// once for all the directions a vertex evaluates. `None` when it depends on them.
    #[inline]
    pub fn constant(&self, kd: Color, ks: Color) -> Option<Color> {
        if ks != Color::ZERO {
            return None;
        }
        match self.model {
            BrdfModel::OriginalPhong
            | BrdfModel::ModifiedPhong { normalized: false }
            | BrdfModel::OriginalBlinnPhong
            | BrdfModel::ModifiedBlinnPhong { normalized: false } => Some(kd),
            BrdfModel::ModifiedPhong { normalized: true } | BrdfModel::ModifiedBlinnPhong { normalized: true } => {
                Some(kd / PI)
            }
            BrdfModel::TorranceSparrow { .. } => None,
        }
    }
}

/// `cos^p α`, α the angle between the mirror direction of `wi` and `wo` (0 past 90°).
#[inline]
fn phong_lobe(wi: Vec3, wo: Vec3, n: Vec3, p: f32) -> f32 {
    let r = -reflect(wi, n);
    r.dot(wo).max(0.0).powf(p)
}

/// `cos^p α_h`, α_h the angle between the normal and the half vector of `wi` and `wo`.
#[inline]
fn blinn_lobe(wi: Vec3, wo: Vec3, n: Vec3, p: f32) -> f32 {
    let h = (wi + wo).normalize_or_zero();
    n.dot(h).max(0.0).powf(p)
}

/// Torrance-Sparrow's `D G / (4 cos θ_i cos θ_o)` for `n·wi > 0`, symmetric in `wi` and `wo`. It needs
/// the viewer above the surface too: below it (a back face seen under the METU rule of unflipped
/// normals) there is none.
fn microfacet(wi: Vec3, wo: Vec3, n: Vec3, p: f32) -> f32 {
    let (cos_i, cos_o) = (n.dot(wi), n.dot(wo));
    let h = (wi + wo).normalize_or_zero();
    let cos_oh = wo.dot(h);
    if cos_o <= 0.0 || cos_oh <= 0.0 {
        return 0.0;
    }
    let cos_h = n.dot(h).max(0.0);
    let d = (p + 2.0) / (2.0 * PI) * cos_h.powf(p);
    let g = (2.0 * cos_h * cos_o / cos_oh).min(2.0 * cos_h * cos_i / cos_oh).min(1.0);
    d * g / (4.0 * cos_i * cos_o)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::{blinn_phong, Material};
    use crate::sampler::Rng;

    const PHONG: BrdfModel = BrdfModel::ModifiedPhong { normalized: false };
    const PHONG_NORM: BrdfModel = BrdfModel::ModifiedPhong { normalized: true };
    const BLINN: BrdfModel = BrdfModel::ModifiedBlinnPhong { normalized: false };
    const BLINN_NORM: BrdfModel = BrdfModel::ModifiedBlinnPhong { normalized: true };
    /// A conductor whose Fresnel reflectance is 1 to within 1e-4 at every angle.
    const TS_MIRROR: BrdfModel = BrdfModel::TorranceSparrow { eta: 0.0, k: 1e4, kd_fresnel: false };

    /// The unit direction at polar angle `deg` from +z, in the xz plane (negative angles towards -x).
    fn dir(deg: f32) -> Vec3 {
        let t = deg.to_radians();
        Vec3::new(t.sin(), 0.0, t.cos())
    }

    /// `f` with grey reflectances `kd`, `ks`, at normal +z.
    fn f(model: BrdfModel, p: f32, kd: f32, ks: f32, wi: Vec3, wo: Vec3) -> f32 {
        let v = Brdf { model, exponent: p }.f(Color::splat(kd), Color::splat(ks), wi, wo, Vec3::Z);
        assert!(v.x == v.y && v.y == v.z, "{v}");
        v.x
    }

    fn close(a: f32, b: f32) -> bool {
        (a - b).abs() <= 1e-5 * b.abs().max(1.0)
    }

    #[test]
    fn brdf_phong_and_blinn_values_at_hand_computed_angles() {
        // θ_i = 60°, θ_o = 30° across the normal: α = 30° (cos² = 3/4), α_h = 15° (cos² = (1 + cos 30°)/2).
        let (wi, wo) = (dir(60.0), dir(-30.0));
        let (cos_i, phong, blinn) = (0.5, 0.75, (1.0 + 0.75_f32.sqrt()) / 2.0);
        let cases = [
            (BrdfModel::OriginalPhong, 0.5 + 0.25 * phong / cos_i),
            (PHONG, 0.5 + 0.25 * phong),
            (PHONG_NORM, 0.5 / PI + 0.25 * 4.0 / (2.0 * PI) * phong),
            (BrdfModel::OriginalBlinnPhong, 0.5 + 0.25 * blinn / cos_i),
            (BLINN, 0.5 + 0.25 * blinn),
            (BLINN_NORM, 0.5 / PI + 0.25 * 10.0 / (8.0 * PI) * blinn),
        ];
        for (model, want) in cases {
            let got = f(model, 2.0, 0.5, 0.25, wi, wo);
            assert!(close(got, want), "{model:?}: {got} != {want}");
        }
        // Past 90° from the mirror direction the Phong lobe is 0; light from below gives nothing.
        assert_eq!(f(PHONG, 2.0, 0.0, 1.0, dir(60.0), dir(-60.0 + 95.0)), 0.0);
        for (model, _) in cases {
            assert_eq!(f(model, 2.0, 0.5, 0.25, -wi, wo), 0.0, "{model:?}");
        }
    }

    #[test]
    fn brdf_torrance_sparrow_value_at_hand_computed_angles() {
        // θ_i = 80°, θ_o = 0°: α_h = 40°, masking G = 2 cos θ_i (< 1); n = 1.5, k = 0 gives
        // F(θ_i) = 0.4861338 by the course's formula (at the half-vector angle, 40°, it would be 0.04).
        let (wi, wo, c80, c40) = (dir(80.0), Vec3::Z, 80_f32.to_radians().cos(), 40_f32.to_radians().cos());
        let (d, g, fr) = (4.0 / (2.0 * PI) * c40 * c40, 2.0 * c80, 0.486_133_8);
        let spec = d * fr * g / (4.0 * c80);
        let ts = |kd_fresnel| BrdfModel::TorranceSparrow { eta: 1.5, k: 0.0, kd_fresnel };
        let got = f(ts(false), 2.0, 0.5, 0.25, wi, wo);
        assert!(close(got, 0.5 / PI + 0.25 * spec), "{got}");
        let got = f(ts(true), 2.0, 0.5, 0.25, wi, wo);
        assert!(close(got, (1.0 - fr) * 0.5 / PI + 0.25 * spec), "kdfresnel: {got}");
        // A viewer below the surface sees the diffuse term only.
        assert!(close(f(ts(false), 2.0, 0.5, 0.25, wi, -wo), 0.5 / PI));
    }

    #[test]
    fn brdf_original_blinn_phong_is_the_default_shading() {
        let m = Material {
            ambient: Color::ZERO,
            diffuse: Color::new(0.5, 0.43, 0.285),
            specular: Color::new(1.0, 0.86, 0.57),
            phong_exponent: 50.0,
            brdf: None,
            roughness: 0.0,
            layer: None,
            degamma: false,
        };
        let with =
            Material { brdf: Some(Brdf { model: BrdfModel::OriginalBlinnPhong, exponent: 50.0 }), layer: None, ..m };
        let mut rng = Rng::for_sample(1, 2, 3, 4);
        for _ in 0..1000 {
            let (wi, wo) = (hemisphere(&mut rng), hemisphere(&mut rng));
            let (a, b) = (m.eval_cos(Vec3::Z, wi, wo), with.eval_cos(Vec3::Z, wi, wo));
            assert_eq!(a, blinn_phong(&m, Vec3::Z, wi, wo));
            assert!(a.abs_diff_eq(b, 1e-5 * a.max_element().max(1.0)), "{a} {b}");
        }
    }

    /// A direction of the upper hemisphere (z > 0.01), uniform in solid angle.
    fn hemisphere(rng: &mut Rng) -> Vec3 {
        let u = rng.next_2d();
        let z = 0.01 + 0.99 * u.x;
        let r = (1.0 - z * z).sqrt();
        let phi = 2.0 * PI * u.y;
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }

    #[test]
    fn brdf_modified_models_are_reciprocal_and_original_ones_are_not() {
        let mut rng = Rng::for_sample(5, 6, 7, 8);
        for model in [PHONG, PHONG_NORM, BLINN, BLINN_NORM] {
            for _ in 0..1000 {
                let (wi, wo) = (hemisphere(&mut rng), hemisphere(&mut rng));
                let (a, b) = (f(model, 20.0, 0.3, 0.7, wi, wo), f(model, 20.0, 0.3, 0.7, wo, wi));
                assert!(close(a, b), "{model:?}: f(wi, wo) = {a}, f(wo, wi) = {b}");
            }
        }
        // The original models divide by the incidence cosine: swapping a 60° and a 30° direction
        // changes the specular term by the ratio of the cosines.
        let (wi, wo) = (dir(60.0), dir(-30.0));
        for model in [BrdfModel::OriginalPhong, BrdfModel::OriginalBlinnPhong] {
            let (a, b) = (f(model, 2.0, 0.0, 1.0, wi, wo), f(model, 2.0, 0.0, 1.0, wo, wi));
            assert!(close(a / b, 0.75_f32.sqrt() / 0.5), "{model:?}: {a} {b}");
        }
    }

    #[test]
    fn brdf_constant_is_f_bit_for_bit_wherever_it_is_given() {
        let mut rng = Rng::for_sample(1, 3, 5, 7);
        let ts = BrdfModel::TorranceSparrow { eta: 1.5, k: 0.5, kd_fresnel: true };
        let models =
            [BrdfModel::OriginalPhong, PHONG, PHONG_NORM, BrdfModel::OriginalBlinnPhong, BLINN, BLINN_NORM, ts];
        let kd = Color::new(0.3, 0.55, 0.71);
        for model in models {
            let b = Brdf { model, exponent: 20.0 };
            assert_eq!(b.constant(kd, Color::splat(0.2)), None, "{model:?} with a specular colour");
            let Some(c) = b.constant(kd, Color::ZERO) else {
                assert_eq!(model, ts);
                continue;
            };
            for _ in 0..100 {
                let (wi, wo) = (hemisphere(&mut rng), hemisphere(&mut rng));
                assert_eq!(
                    c.to_array().map(f32::to_bits),
                    b.f(kd, Color::ZERO, wi, wo, Vec3::Z).to_array().map(f32::to_bits)
                );
                // `f` answers by `constant` there: the model's own formula must give the same bits.
                let formula = b.formula(kd, Color::ZERO, wi, wo, Vec3::Z, wi.z);
                assert_eq!(c.to_array().map(f32::to_bits), formula.to_array().map(f32::to_bits), "{model:?}");
            }
        }
    }

    #[test]
    fn brdf_torrance_sparrow_is_reciprocal_but_for_its_fresnel_factor() {
        let ts = BrdfModel::TorranceSparrow { eta: 1.5, k: 0.5, kd_fresnel: false };
        let mut rng = Rng::for_sample(9, 10, 11, 12);
        for _ in 0..1000 {
            let (wi, wo) = (hemisphere(&mut rng), hemisphere(&mut rng));
            // Without its Fresnel factor the specular term is symmetric.
            let spec = |wi: Vec3, wo: Vec3| f(ts, 20.0, 0.0, 1.0, wi, wo) / fresnel_conductor(wi.z, 1.5, 0.5);
            let (a, b) = (spec(wi, wo), spec(wo, wi));
            assert!(close(a, b), "{a} {b}");
            // With a Fresnel reflectance of 1 everywhere, the whole model is.
            let (a, b) = (f(TS_MIRROR, 20.0, 0.3, 0.7, wi, wo), f(TS_MIRROR, 20.0, 0.3, 0.7, wo, wi));
            assert!(close(a, b), "{a} {b}");
        }
        let (wi, wo) = (dir(80.0), dir(-10.0));
        let (a, b) = (f(ts, 20.0, 0.0, 1.0, wi, wo), f(ts, 20.0, 0.0, 1.0, wo, wi));
        assert!(!close(a, b), "F(θ_i) differs from F(θ_o): {a} {b}");
    }

    /// The directional albedo `∫ f cos θ_i dω_i` seen from `wo` (midpoint rule in θ and φ, fine enough
    /// for lobes of exponent 200).
    fn albedo(model: BrdfModel, p: f32, wo: Vec3) -> f64 {
        let (nt, np) = (1024, 512);
        let (dt, dp) = (std::f64::consts::FRAC_PI_2 / nt as f64, 2.0 * std::f64::consts::PI / np as f64);
        let mut sum = 0.0;
        for i in 0..nt {
            let t = (i as f64 + 0.5) * dt;
            let mut ring = 0.0;
            for j in 0..np {
                let ph = (j as f64 + 0.5) * dp;
                let wi = Vec3::new((t.sin() * ph.cos()) as f32, (t.sin() * ph.sin()) as f32, t.cos() as f32);
                ring += f(model, p, 0.0, 1.0, wi, wo) as f64;
            }
            sum += ring * t.cos() * t.sin();
        }
        sum * dt * dp
    }

    #[test]
    fn brdf_normalized_models_and_torrance_sparrow_reflect_no_more_than_they_receive() {
        for p in [1.0, 10.0, 50.0, 200.0] {
            for deg in [0.0, 30.0, 60.0, 85.0] {
                let wo = dir(deg);
                let phong = albedo(PHONG_NORM, p, wo);
                assert!(phong <= 1.0 + 1e-3, "normalized Phong, p {p}, θ_o {deg}: albedo {phong}");
                let ts = albedo(TS_MIRROR, p, wo);
                assert!(ts <= 1.0 + 1e-3, "Torrance-Sparrow, p {p}, θ_o {deg}: albedo {ts}");
                // (p+8)/8π is an approximation of Blinn-Phong's normalization (Akenine-Möller et al.):
                // it overshoots by up to 7.5% near normal incidence (exactly (p+8)/p for large p).
                let blinn = albedo(BLINN_NORM, p, wo);
                assert!(blinn <= 1.08, "normalized Blinn-Phong, p {p}, θ_o {deg}: albedo {blinn}");
            }
            // At normal incidence the normalized Phong lobe reflects everything: the integration is exact
            // enough to tell.
            let head_on = albedo(PHONG_NORM, p, Vec3::Z);
            assert!((head_on - 1.0).abs() < 2e-3, "p {p}: {head_on}");
        }
        // Not normalized, the same lobes create light.
        assert!(albedo(PHONG, 1.0, Vec3::Z) > 2.0);
        assert!(albedo(BLINN, 1.0, Vec3::Z) > 1.5);
    }
}
