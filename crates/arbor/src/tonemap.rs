//! Tone mapping: a high-dynamic-range film to display values, the photographic operator of Reinhard,
//! Stark, Shirley and Ferwerda, "Photographic tone reproduction for digital images" (SIGGRAPH 2002), in
//! its global form, followed by the course's saturation and gamma steps (CENG 795 hw5).
//!
//! For luminance `Y = 0.2126 R + 0.7152 G + 0.0722 B`: the log-average `Ȳ = exp(mean(ln(δ + Y)))`
//! (the paper's equation 1), the scaled luminance `L = key · Y / Ȳ` (equation 2), then
//! `Ld = L (1 + L / Lw²) / (1 + L)` (equation 4) with `Lw` the scaled luminance that `burn` percent of
//! the pixels exceed, or `Ld = L / (1 + L)` (equation 3) when `burn` is 0. Each channel becomes
//! `Ld · (C / Y)^saturation`, is clamped to `[0, 1]` and raised to `1 / gamma`. A pixel of zero
//! luminance stays black. Without black pixels the operator is invariant to the film's overall scale.

use crate::film::Film;
use crate::math::{Color, Vec3};

/// The luminance weights of linear sRGB (Rec. 709 primaries).
const LUMINANCE: Vec3 = Vec3::new(0.2126, 0.7152, 0.0722);

/// Keeps the logarithm of black pixels finite, in units of the scene's radiance; small against any
/// luminance a render shows, but it sets how much black pixels pull the log-average down.
const DELTA: f64 = 1e-6;

/// The tone mapping operators Arbor knows (the scene file's `TMO`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Operator {
    /// Reinhard et al.'s global photographic operator.
    Photographic,
}

/// A camera's tone mapping: operator, key value, burn-out percentage, saturation and gamma.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tonemap {
    /// The operator.
    pub operator: Operator,
    /// The key: the display luminance the log-average maps to before compression (0.18 in the paper).
    pub key: f32,
    /// Share of pixels, in percent (0 to 100), allowed to burn out to white.
    pub burn_percent: f32,
    /// Exponent on the chromaticity `C / Y`: 1 keeps colours, 0 greys them.
    pub saturation: f32,
    /// Display gamma (positive).
    pub gamma: f32,
    /// The film value of one unit of the scene's radiance (its radiance scale, 1/255 for the course's
    /// files): `δ` of the log-average is a millionth of a scene unit, so that black pixels weigh as in
    /// the course's renderer, whose films hold the scene's radiance as it is.
    pub unit: f32,
}

/// A film's exposure under a [`Tonemap`] ([`Tonemap::exposure`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Exposure {
    /// Scaled luminance per unit of the film's luminance.
    pub scale: f64,
    /// The scaled luminance that burns out to white; `None` without burn-out.
    pub white: Option<f64>,
}

impl Exposure {
    /// This exposure made `k` times brighter: the scale and the burn-out white together, as the scaled
    /// luminance of a film `k` times brighter would give them.
    pub fn scaled(self, k: f64) -> Exposure {
        Exposure { scale: self.scale * k, white: self.white.map(|w| w * k) }
    }
}

/// Luminance of a linear sRGB colour.
pub fn luminance(c: Color) -> f32 {
    c.dot(LUMINANCE)
}

impl Tonemap {
    /// The tone mapping of the PNG written beside a high-dynamic-range image whose camera names none:
    /// the settings of the course's own HDR scenes (key 0.18, 1% burn-out, saturation 1, gamma 2.2).
    pub const PREVIEW: Tonemap = Tonemap {
        operator: Operator::Photographic,
        key: 0.18,
        burn_percent: 1.0,
        saturation: 1.0,
        gamma: 2.2,
        unit: 1.0,
    };

    /// The same tone mapping for a film whose one unit of scene radiance is `unit`.
    pub fn in_units(self, unit: f32) -> Tonemap {
        Tonemap { unit, ..self }
    }

    /// The display film: every channel in `[0, 1]`, gamma applied, ready for 8-bit quantisation.
    pub fn apply(&self, film: &Film) -> Film {
        self.apply_exposure(film, self.exposure(film))
    }

    /// What the operator takes from a film as a whole: the scale from luminance to scaled luminance
    /// (key over log-average) and the burn-out white.
    pub fn exposure(&self, film: &Film) -> Exposure {
        let lum: Vec<f32> = film.pixels.iter().map(|&c| sanitize(luminance(c))).collect();
        let scale = self.key as f64 / log_average(&lum, DELTA * self.unit as f64);
        Exposure { scale, white: self.white(&lum, scale) }
    }

    /// `film` under the exposure of another film (the same tone curve for several images of one scene,
    /// whose noise would move their own log-averages and burn-out percentiles).
    pub fn apply_exposure(&self, film: &Film, e: Exposure) -> Film {
        let pixels = film.pixels.iter().map(|&c| self.map_pixel(c, sanitize(luminance(c)), e.scale, e.white)).collect();
        Film { width: film.width, height: film.height, pixels }
    }

    /// The scaled luminance that `burn_percent` percent of the pixels exceed; `None` for no burn-out.
    fn white(&self, lum: &[f32], scale: f64) -> Option<f64> {
        if self.burn_percent <= 0.0 || lum.is_empty() {
            return None;
        }
        let mut sorted = lum.to_vec();
        sorted.sort_unstable_by(f32::total_cmp);
        let keep = (100.0 - self.burn_percent as f64) / 100.0;
        let index = ((keep * sorted.len() as f64) as usize).min(sorted.len() - 1);
        Some(sorted[index] as f64 * scale)
    }

    fn map_pixel(&self, c: Color, y: f32, scale: f64, white: Option<f64>) -> Color {
        if y <= 0.0 {
            return Color::ZERO;
        }
        let l = y as f64 * scale;
        let ld = match white {
            Some(w) if w > 0.0 => l * (1.0 + l / (w * w)) / (1.0 + l),
            _ => l / (1.0 + l),
        };
        let channel = |v: f32| {
            let ratio = (sanitize(v) as f64 / y as f64).powf(self.saturation as f64);
            ((ld * ratio).clamp(0.0, 1.0)).powf(1.0 / self.gamma as f64) as f32
        };
        Color::new(channel(c.x), channel(c.y), channel(c.z))
    }
}

/// `exp(mean(ln(δ + Y)))` over the pixels (the paper's equation 1).
fn log_average(lum: &[f32], delta: f64) -> f64 {
    if lum.is_empty() {
        return 1.0;
    }
    let sum: f64 = lum.iter().map(|&y| (delta + y as f64).ln()).sum();
    (sum / lum.len() as f64).exp()
}

/// Negative and NaN values (never produced by shading, possible in a read image) count as black, and
/// infinite ones as the largest finite value, so that one bad pixel cannot blank the image.
fn sanitize(v: f32) -> f32 {
    if v.is_nan() || v <= 0.0 {
        0.0
    } else {
        v.min(f32::MAX)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn film(pixels: Vec<Color>) -> Film {
        Film { width: pixels.len() as u32, height: 1, pixels }
    }

    fn photographic(key: f32, burn_percent: f32, saturation: f32, gamma: f32) -> Tonemap {
        Tonemap { operator: Operator::Photographic, key, burn_percent, saturation, gamma, unit: 1.0 }
    }

    fn close(a: f32, b: f64) -> bool {
        (a as f64 - b).abs() < 1e-5
    }

    #[test]
    fn tonemap_in_units_maps_a_scaled_film_as_the_film_in_scene_units() {
        // Black pixels pull the log-average down by ln(δ): δ is a millionth of a scene unit, so a film
        // holding radiance / 255 maps as the radiance itself would, and not without its unit.
        let scene = [Color::ZERO, Color::ZERO, Color::splat(0.5), Color::new(2.0, 1.0, 0.5), Color::splat(9.0)];
        let film_of = |k: f32| film(scene.iter().map(|&c| c * k).collect());
        let tm = photographic(0.18, 0.0, 1.0, 2.2);
        let want = tm.apply(&film_of(1.0)).to_rgb8();
        assert_eq!(tm.in_units(1.0 / 255.0).apply(&film_of(1.0 / 255.0)).to_rgb8(), want);
        assert_ne!(tm.apply(&film_of(1.0 / 255.0)).to_rgb8(), want);
    }

    #[test]
    fn tonemap_uniform_grey_maps_the_key_through_equation_3() {
        // Every pixel at the log-average: L = key = 0.18, Ld = 0.18 / 1.18, gamma 1.
        let out = photographic(0.18, 0.0, 1.0, 1.0).apply(&film(vec![Color::splat(7.0); 4]));
        for p in out.pixels {
            assert!(close(p.x, 0.18 / 1.18) && close(p.y, 0.18 / 1.18) && close(p.z, 0.18 / 1.18), "{p}");
        }
    }

    #[test]
    fn tonemap_two_greys_by_hand_with_burn_out() {
        // Y = 1 and 4: log-average 2; key 0.5 gives L = 0.25 and 1. Burn 50%: the sorted luminances
        // are [1, 4], index floor(0.5 * 2) = 1, Lw = 4 * 0.25 = 1, and equation 4 gives
        // 0.25 * (1 + 0.25) / 1.25 = 0.25 and 1 * (1 + 1) / 2 = 1.
        let out = photographic(0.5, 50.0, 1.0, 1.0).apply(&film(vec![Color::ONE, Color::splat(4.0)]));
        assert!(close(out.pixels[0].x, 0.25), "{}", out.pixels[0]);
        assert!(close(out.pixels[1].x, 1.0), "{}", out.pixels[1]);
        // Gamma 2 takes square roots: 0.25 -> 0.5.
        let out = photographic(0.5, 50.0, 1.0, 2.0).apply(&film(vec![Color::ONE, Color::splat(4.0)]));
        assert!(close(out.pixels[0].x, 0.5));
    }

    #[test]
    fn tonemap_saturation_scales_the_chromaticity() {
        // One pixel (R, G, B) = (2, 1, 0): Y = 0.4252 + 0.7152 = 1.1404, which is also the log-average,
        // so L = key = 1 and Ld = 1/2. Saturation 1: R = 0.5 * 2 / 1.1404; saturation 0: grey 0.5.
        let c = Color::new(2.0, 1.0, 0.0);
        let y = 2.0 * 0.2126 + 0.7152;
        let out = photographic(1.0, 0.0, 1.0, 1.0).apply(&film(vec![c]));
        assert!(close(out.pixels[0].x, 0.5 * 2.0 / y) && close(out.pixels[0].y, 0.5 / y));
        assert_eq!(out.pixels[0].z, 0.0);
        let grey = photographic(1.0, 0.0, 0.0, 1.0).apply(&film(vec![c]));
        assert!(close(grey.pixels[0].x, 0.5) && close(grey.pixels[0].z, 0.5), "{}", grey.pixels[0]);
    }

    #[test]
    fn tonemap_is_invariant_to_scale_and_keeps_black_black() {
        let pixels = vec![Color::new(0.3, 0.2, 0.1), Color::new(5.0, 6.0, 7.0), Color::splat(0.01)];
        let tm = photographic(0.18, 1.0, 1.0, 2.2);
        let a = tm.apply(&film(pixels.clone()));
        let b = tm.apply(&film(pixels.iter().map(|&c| c * 1000.0).collect()));
        let black = tm.apply(&film(vec![Color::ZERO, Color::ONE]));
        assert_eq!(black.pixels[0], Color::ZERO);
        for (p, q) in a.pixels.iter().zip(&b.pixels) {
            assert!((*p - *q).abs().max_element() < 1e-3, "{p} vs {q}");
        }
    }
}
