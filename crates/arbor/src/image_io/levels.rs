//! Images as display levels (0 to 255, unrounded) for comparing them: an 8-bit image as it is, a
//! high-dynamic-range one (EXR, HDR: radiance) through one global curve that its reference fixes.
//!
//! The curve ([`DisplayCurve`]) is Reinhard et al.'s simple global operator (SIGGRAPH 2002, equations 1-3:
//! key 0.18 over the log-average luminance, `L / (1 + L)`, no burn-out), then gamma 2.2, with the
//! exposure taken from the reference alone. Every image compared with that reference goes through the
//! same curve, so that neither an image's noise nor its sample count moves its exposure (a noisier
//! render has a lower log-average: its own curve would brighten it).
//!
//! Block means ([`BlockLevels`]) are taken before the curve, in linear values, then mapped: noise
//! averages out in radiance, where the estimators are unbiased, not after a non-linear curve that
//! clips fireflies depending on the samples. An 8-bit image's block means are those of its levels. Blocks
//! at the right and bottom edges are cut short and averaged over the pixels they have. Cost: one pass
//! over the pixels, one sort-free log-average for the curve.

use crate::film::Film;
use crate::math::Color;
use crate::tonemap::{Exposure, Operator, Tonemap};

/// The operator of [`DisplayCurve`]: key 0.18, no burn-out, colours kept, gamma 2.2.
const CURVE: Tonemap =
    Tonemap { operator: Operator::Photographic, key: 0.18, burn_percent: 0.0, saturation: 1.0, gamma: 2.2, unit: 1.0 };

/// One global tone curve for a reference and everything compared with it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DisplayCurve {
    exposure: Exposure,
}

impl DisplayCurve {
    /// The curve whose exposure `reference` (linear values) fixes.
    pub fn of_reference(reference: &Film) -> DisplayCurve {
        DisplayCurve { exposure: CURVE.exposure(reference) }
    }

    /// `film` (linear values) as 8-bit levels, row-major RGB, rounded as images are written.
    pub fn rgb8(&self, film: &Film) -> Vec<u8> {
        CURVE.apply_exposure(film, self.exposure).to_rgb8()
    }

    /// Colours (linear values) as unrounded levels.
    fn levels(&self, colours: Vec<Color>) -> Vec<[f64; 3]> {
        let film = Film { width: colours.len() as u32, height: 1, pixels: colours };
        CURVE
            .apply_exposure(&film, self.exposure)
            .pixels
            .iter()
            .map(|c| c.to_array().map(|v| 255.0 * v as f64))
            .collect()
    }
}

/// An image's block means in display levels, row by row, and the pixels each block covers.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockLevels {
    /// The side of a block, in pixels.
    pub block: u32,
    /// Each block's mean per channel, in levels.
    pub means: Vec<[f64; 3]>,
    /// Each block's pixel count (edge blocks have fewer).
    pub pixels: Vec<u32>,
}

impl BlockLevels {
    /// The block means of a row-major 8-bit RGB image.
    ///
    /// # Panics
    /// When `rgb` is not `3 * width * height` bytes or `block` is 0.
    pub fn of_rgb8(rgb: &[u8], width: u32, height: u32, block: u32) -> BlockLevels {
        assert_eq!(rgb.len(), 3 * width as usize * height as usize, "image is not {width}x{height} RGB");
        let (sums, pixels) = block_sums(width, height, block, |i| [0, 1, 2].map(|c| f64::from(rgb[3 * i + c])));
        let means = sums.iter().zip(&pixels).map(|(s, &n)| s.map(|v| v / n as f64)).collect();
        BlockLevels { block, means, pixels }
    }

    /// The block means of `film` (linear values), taken before `curve` maps them to levels.
    ///
    /// # Panics
    /// When `block` is 0.
    pub fn of_film(film: &Film, block: u32, curve: &DisplayCurve) -> BlockLevels {
        let (sums, pixels) =
            block_sums(film.width, film.height, block, |i| film.pixels[i].to_array().map(|v| v as f64));
        let linear = sums.iter().zip(&pixels).map(|(s, &n)| {
            let [r, g, b] = s.map(|v| (v / n as f64) as f32);
            Color::new(r, g, b)
        });
        BlockLevels { block, means: curve.levels(linear.collect()), pixels }
    }

    /// The mean per channel over all pixels (blocks weighed by their pixels), in levels.
    pub fn mean(&self) -> [f64; 3] {
        let total: f64 = self.pixels.iter().map(|&n| n as f64).sum();
        let sum = |c: usize| self.means.iter().zip(&self.pixels).map(|(m, &n)| m[c] * n as f64).sum::<f64>();
        [0, 1, 2].map(|c| if total > 0.0 { sum(c) / total } else { 0.0 })
    }

    /// The mean absolute difference of block means from `other`'s, over blocks and channels.
    ///
    /// # Panics
    /// When the two have different blocks.
    pub fn mean_abs_diff(&self, other: &BlockLevels) -> f64 {
        assert_eq!(self.pixels, other.pixels, "block means of images of different sizes or blocks");
        let n = (3 * self.means.len()).max(1) as f64;
        let sum: f64 =
            self.means.iter().zip(&other.means).flat_map(|(p, q)| (0..3).map(move |i| (p[i] - q[i]).abs())).sum();
        sum / n
    }
}

/// Per-block channel sums of the `width` x `height` pixels that `pixel(i)` gives (row-major index), and
/// each block's pixel count.
fn block_sums(width: u32, height: u32, block: u32, pixel: impl Fn(usize) -> [f64; 3]) -> (Vec<[f64; 3]>, Vec<u32>) {
    assert!(block > 0, "a block is at least 1 pixel wide");
    let (w, h, k) = (width as usize, height as usize, block as usize);
    let bw = w.div_ceil(k);
    let mut sums = vec![[0.0; 3]; bw * h.div_ceil(k)];
    let mut pixels = vec![0u32; sums.len()];
    for y in 0..h {
        for x in 0..w {
            let b = (y / k) * bw + x / k;
            let p = pixel(y * w + x);
            (0..3).for_each(|c| sums[b][c] += p[c]);
            pixels[b] += 1;
        }
    }
    (sums, pixels)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_rgb8_blocks_cover_edge_blocks_with_the_pixels_they_have() {
        // 3x2 pixels, blocks of 2: a 2x2 block and a 1x2 one.
        let rgb: Vec<u8> = [10u8, 20, 30, 40, 50, 60].iter().flat_map(|&v| [v, 0, 255]).collect();
        let m = BlockLevels::of_rgb8(&rgb, 3, 2, 2);
        assert_eq!(m.means, vec![[(10.0 + 20.0 + 40.0 + 50.0) / 4.0, 0.0, 255.0], [45.0, 0.0, 255.0]]);
        assert_eq!(m.pixels, vec![4, 2]);
        assert_eq!(m.mean()[0], (10.0 + 20.0 + 30.0 + 40.0 + 50.0 + 60.0) / 6.0);
    }

    #[test]
    fn levels_curve_is_fixed_by_the_reference_and_blocks_average_before_it() {
        let grey = |v: f32, n: usize| Film { width: n as u32, height: 1, pixels: vec![Color::splat(v); n] };
        // A flat reference maps to the key: 0.18 / 1.18 before gamma.
        let reference = grey(50.0, 4);
        let curve = DisplayCurve::of_reference(&reference);
        let key = 255.0 * (0.18f64 / 1.18).powf(1.0 / 2.2);
        let flat = BlockLevels::of_film(&reference, 2, &curve);
        assert!(flat.means.iter().flatten().all(|&v| (v - key).abs() < 1e-3), "{flat:?}");
        // Twice the radiance is brighter under the same curve (its own would map it to the key again).
        let bright = BlockLevels::of_film(&grey(100.0, 4), 2, &curve);
        assert!(bright.means[0][0] > key + 10.0, "{bright:?}");
        // A block of 0 and 100 is the mean of 50 mapped, not the mean of the mapped pixels.
        let mut noisy = grey(0.0, 4);
        noisy.pixels[1] = Color::splat(100.0);
        noisy.pixels[3] = Color::splat(100.0);
        let blocks = BlockLevels::of_film(&noisy, 2, &curve);
        assert!(blocks.mean_abs_diff(&flat) < 1e-3, "{blocks:?}");
        assert_eq!(curve.rgb8(&reference), vec![key.round() as u8; 12]);
    }
}
