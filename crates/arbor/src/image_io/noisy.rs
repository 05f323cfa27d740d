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

use super::levels::{BlockLevels, DisplayCurve};
use crate::film::Film;

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
}

impl NoisyComparison {
    /// Whether the rule holds.
    pub fn passes(&self) -> bool {
        self.mad <= self.noise + NOISE_MARGIN && self.bias.iter().all(|b| b.abs() <= BIAS_LIMIT)
    }

    /// One line: the two differences, the bias and the verdict.
    pub fn summary(&self) -> String {
        format!(
            "{k}x{k} blocks: render vs reference {:.2} levels, seed vs seed {:.2} (limit {:.2}); bias {:+.2} \
             {:+.2} {:+.2} (limit ±{BIAS_LIMIT}): {}",
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
}
