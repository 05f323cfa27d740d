//! Comparing a render with a noisy reference (a path-traced one), as project issue 31 defines it: both
//! images are signal plus noise at the reference's own sample count N, so no fixed threshold separates a
//! wrong render from an unlucky one. The noise is measured instead: the same render with another seed.
//! The render (seed 1) must be as close to the reference as it is to its second seed, plus
//! [`NOISE_MARGIN`] levels, with every channel's mean signed difference within [`BIAS_LIMIT`] levels.
//!
//! Everything is on KxK-pixel block means in display levels ([`super::levels`]): of the 8-bit values for
//! 8-bit images (a PNG reference against PNG renders), and for high-dynamic-range images taken in linear
//! radiance then put through one global curve that the reference fixes, so that neither a render's noise
//! nor its sample count moves its exposure.
//!
//! A reference that is only an 8-bit image written through the course's tone curve (the photographic
//! operator, [`crate::tonemap`]) holds an exposure its renderer took from its own noisy radiance: the
//! log-average, which the share of black (unlit, noisy) pixels pulls down. A render's own log-average
//! moves with its own noise the same way, so [`compare_noisy_tonemapped`] shows both seeds' radiance
//! under one exposure, the one that brings them closest to the reference (a single factor on the
//! first seed's own exposure). The fit hides nothing the image could show: the curve maps `key · Y /
//! Ȳ`, so a render wrong by a constant factor writes the same image under its own exposure anyway;
//! every difference in the distribution of light is still measured block by block. The factor is
//! reported ([`NoisyComparison::exposure`]).

use super::levels::{BlockLevels, DisplayCurve};
use crate::film::Film;
use crate::tonemap::Tonemap;

/// Levels the render may be farther from the reference than from its second seed.
pub const NOISE_MARGIN: f64 = 1.0;
/// Largest mean signed difference per channel, in levels.
pub const BIAS_LIMIT: f64 = 2.0;

/// The outcome of [`compare_noisy`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoisyComparison {
    /// Block side in pixels.
    pub block: u32,
    /// Mean absolute difference of block means, render against the reference.
    pub mad: f64,
    /// Mean absolute difference of block means between the render and its second seed: the noise.
    pub noise: f64,
    /// Mean signed difference per channel, render minus reference.
    pub bias: [f64; 3],
    /// For [`compare_noisy_tonemapped`]: the fitted exposure over the first seed's own.
    pub exposure: Option<f64>,
}

impl NoisyComparison {
    /// Whether the rule holds.
    pub fn passes(&self) -> bool {
        self.mad <= self.noise + NOISE_MARGIN && self.bias.iter().all(|b| b.abs() <= BIAS_LIMIT)
    }

    /// One line: the two differences, the bias and the verdict.
    pub fn summary(&self) -> String {
        format!(
            "{k}x{k} blocks{}: render vs reference {:.2} levels, seed vs seed {:.2} (limit {:.2}); bias {:+.2} \
             {:+.2} {:+.2} (limit ±{BIAS_LIMIT}): {}",
            self.exposure.map_or(String::new(), |e| format!(" at {e:.3} times the render's own exposure")),
            self.mad,
            self.noise,
            self.noise + NOISE_MARGIN,
            self.bias[0],
            self.bias[1],
            self.bias[2],
            if self.passes() { "OK" } else { "FAIL" },
            k = self.block
        )
    }
}

/// The rule on block means already in levels: `render` and `other_seed` are one render with two seeds.
///
/// # Panics
/// When the three have different blocks.
pub fn compare_noisy(reference: &BlockLevels, render: &BlockLevels, other_seed: &BlockLevels) -> NoisyComparison {
    let (r, m) = (reference.mean(), render.mean());
    NoisyComparison {
        block: reference.block,
        mad: render.mean_abs_diff(reference),
        noise: render.mean_abs_diff(other_seed),
        bias: [0, 1, 2].map(|c| m[c] - r[c]),
        exposure: None,
    }
}

/// [`compare_noisy`] of three row-major 8-bit RGB images of one size.
///
/// # Panics
/// When an image is not `3 * width * height` bytes or `block` is 0.
pub fn compare_noisy_rgb8(
    reference: &[u8],
    render: &[u8],
    other_seed: &[u8],
    width: u32,
    height: u32,
    block: u32,
) -> NoisyComparison {
    let means = |img: &[u8]| BlockLevels::of_rgb8(img, width, height, block);
    compare_noisy(&means(reference), &means(render), &means(other_seed))
}

/// [`compare_noisy`] of three films of linear radiance of one size, under the curve `reference` fixes.
///
/// # Panics
/// When the films differ in size or `block` is 0.
pub fn compare_noisy_hdr(reference: &Film, render: &Film, other_seed: &Film, block: u32) -> NoisyComparison {
    let curve = DisplayCurve::of_reference(reference);
    let means = |f: &Film| BlockLevels::of_film(f, block, &curve);
    compare_noisy(&means(reference), &means(render), &means(other_seed))
}

/// [`compare_noisy`] of an 8-bit `reference` of `width` x `height` pixels written through `tonemap` and
/// two seeds' films of radiance shown through it under one exposure fitted to the reference (module
/// doc): the factor on the first seed's own exposure (scale and burn-out white alike) that minimises
/// the two seeds' mean absolute block difference from the reference, over 1/4 to 4.
///
/// # Panics
/// When the images differ in size or `block` is 0.
pub fn compare_noisy_tonemapped(
    reference: &[u8],
    tonemap: &Tonemap,
    render: &Film,
    other_seed: &Film,
    block: u32,
) -> NoisyComparison {
    let (w, h) = (render.width, render.height);
    let reference = BlockLevels::of_rgb8(reference, w, h, block);
    let own = tonemap.exposure(render);
    let levels =
        |f: &Film, k: f64| BlockLevels::of_rgb8(&tonemap.apply_exposure(f, own.scaled(k)).to_rgb8(), w, h, block);
    let cost = |x: f64| {
        let k = x.exp();
        levels(render, k).mean_abs_diff(&reference) + levels(other_seed, k).mean_abs_diff(&reference)
    };
    let x = minimise(cost, -4f64.ln(), 4f64.ln());
    let k = x.exp();
    let c = compare_noisy(&reference, &levels(render, k), &levels(other_seed, k));
    NoisyComparison { exposure: Some(k), ..c }
}

/// The `x` in `[lo, hi]` where `f` is least: the best of 33 even steps, then a golden-section search
/// between its neighbours (the cost is piecewise constant at 8-bit steps, so only near-unimodal).
fn minimise(f: impl Fn(f64) -> f64, lo: f64, hi: f64) -> f64 {
    const STEPS: usize = 32;
    let step = (hi - lo) / STEPS as f64;
    let grid: Vec<f64> = (0..=STEPS).map(|i| f(lo + step * i as f64)).collect();
    let best = (0..=STEPS).min_by(|&a, &b| grid[a].total_cmp(&grid[b])).unwrap_or(0);
    let (mut a, mut b) = (lo + step * best.saturating_sub(1) as f64, lo + step * (best + 1).min(STEPS) as f64);
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..24 {
        if fc <= fd {
            (b, d, fd) = (d, c, fc);
            c = b - g * (b - a);
            fc = f(c);
        } else {
            (a, c, fc) = (c, d, fd);
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    let mid = (a + b) / 2.0;
    // The grid's best stays the answer unless the refinement found at least as good.
    if f(mid) <= grid[best] {
        mid
    } else {
        lo + step * best as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Color;

    #[test]
    fn noisy_rule_passes_within_the_seed_noise_and_fails_on_a_bias() {
        let (w, h) = (32u32, 32u32);
        let n = (w * h) as usize;
        let flat = |v: u8| vec![v; 3 * n];
        let reference = flat(100);
        // Seeds 6 levels apart, the render 1 from the reference.
        let ok = compare_noisy_rgb8(&reference, &flat(101), &flat(95), w, h, 16);
        assert_eq!((ok.mad, ok.noise, ok.bias), (1.0, 6.0, [1.0; 3]));
        assert!(ok.passes(), "{}", ok.summary());
        // Within the noise but biased by 3 levels everywhere.
        let biased = compare_noisy_rgb8(&reference, &flat(103), &flat(97), w, h, 16);
        assert!(!biased.passes(), "{}", biased.summary());
        // Seeds that agree leave only the margin.
        let tight = compare_noisy_rgb8(&reference, &flat(102), &flat(102), w, h, 16);
        assert!(!tight.passes() && tight.summary().ends_with("FAIL"), "{}", tight.summary());
    }

    #[test]
    fn noisy_hdr_rule_judges_radiance_under_the_reference_curve() {
        let film =
            |v: &[f32]| Film { width: v.len() as u32, height: 1, pixels: v.iter().map(|&x| Color::splat(x)).collect() };
        let reference = film(&[10.0; 8]);
        // Noise that averages out in each 4-pixel block: blocks equal the reference's in radiance.
        let a = film(&[0.0, 20.0, 0.0, 20.0, 5.0, 15.0, 5.0, 15.0]);
        let b = film(&[20.0, 0.0, 20.0, 0.0, 15.0, 5.0, 15.0, 5.0]);
        let same = compare_noisy_hdr(&reference, &a, &b, 4);
        assert!(same.mad < 1e-3 && same.noise < 1e-3 && same.passes(), "{}", same.summary());
        // Twice the radiance fails although its own exposure would show it exactly as the reference.
        let bright = compare_noisy_hdr(&reference, &film(&[20.0; 8]), &film(&[20.0; 8]), 4);
        assert!(!bright.passes() && bright.bias[0] > 10.0, "{}", bright.summary());
    }

    /// A 32x32 film of a smooth ramp from 0.05 to 4.05, times `right` on its right half.
    fn ramp(right: f32) -> Film {
        let pixels = (0..32 * 32)
            .map(|i| {
                let (x, y) = (i % 32, i / 32);
                let v = 0.05 + (x + 32 * y) as f32 / 256.0;
                Color::new(v, 0.8 * v, 0.6 * v) * if x >= 16 { right } else { 1.0 }
            })
            .collect();
        Film { width: 32, height: 32, pixels }
    }

    #[test]
    fn tonemapped_rule_fits_the_reference_exposure_and_still_sees_the_light_move() {
        let tm = Tonemap { burn_percent: 1.0, ..Tonemap::PREVIEW };
        let film = ramp(1.0);
        let own = tm.exposure(&film);
        let reference = tm.apply_exposure(&film, own.scaled(1.3)).to_rgb8();
        // Under its own exposure the same radiance is a biased image...
        let plain = tm.apply(&film).to_rgb8();
        assert!(!compare_noisy_rgb8(&reference, &plain, &plain, 32, 32, 8).passes());
        // ...and under the fitted one it is the reference.
        let c = compare_noisy_tonemapped(&reference, &tm, &film, &film, 8);
        let k = c.exposure.unwrap();
        assert!((k / 1.3 - 1.0).abs() < 0.02 && c.mad < 0.2 && c.passes(), "{k} {}", c.summary());
        // Light moved from one half to the other is no exposure: it fails at the best one.
        let moved = compare_noisy_tonemapped(&reference, &tm, &ramp(1.5), &ramp(1.5), 8);
        assert!(!moved.passes(), "{}", moved.summary());
    }

    #[test]
    fn minimise_finds_the_least_of_a_bowl_and_of_a_step() {
        let x = minimise(|x| (x - 0.37).powi(2), -1.0, 1.0);
        assert!((x - 0.37).abs() < 1e-4, "{x}");
        let step = minimise(|x| if x < -0.5 { 1.0 } else { 2.0 }, -1.0, 1.0);
        assert!(step < -0.5, "{step}");
    }
}
