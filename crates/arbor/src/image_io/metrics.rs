//! How far an image is from its reference, in 8-bit levels: PSNR, RMSE, the largest channel difference,
//! the share of pixels that differ by more than a threshold, and the bias (the mean signed difference per
//! channel, image minus reference).
//!
//! All statistics are over the three channels of every pixel (alpha is never compared: [`compare_files`]
//! reads both images as 8-bit RGB with [`read`](fn@super::read), within the pixel budget it is given). PSNR uses a peak of 255:
//! `10 log10(255^2 / MSE)`, infinite for identical images. A pixel is "off" when any of its channels
//! differs by strictly more than the threshold, so threshold 0 counts every difference. Cost: one pass.
//!
//! An image rendered with random samples is noisy, so it cannot match a reference pixel for pixel; but
//! noise averages out over an area while a real error (a missing light, a wrong colour) does not.
//! [`compare_blocks_rgb8`] therefore compares the mean of each KxK-pixel block per channel (blocks at the
//! right and bottom edges are cut short and averaged over the pixels they have); a block is off when a
//! channel's mean differs by strictly more than the threshold. With K = 1 that is the pixel rule.

use std::path::Path;

use super::levels::BlockLevels;
use super::ImageLimits;
use crate::error::{Error, Result};
use crate::film::Film;
use crate::math::Color;

/// The difference between an image and its reference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Comparison {
    /// Width in pixels of both images.
    pub width: u32,
    /// Height in pixels of both images.
    pub height: u32,
    /// Peak signal-to-noise ratio in dB; infinite when the images are equal.
    pub psnr: f64,
    /// Root mean square difference, in 8-bit levels.
    pub rmse: f64,
    /// The largest difference of any channel, in levels.
    pub max_diff: u8,
    /// Pixels with a channel differing by more than the threshold.
    pub pixels_off: usize,
    /// `pixels_off` divided by the pixel count (0 for an empty image).
    pub share_off: f64,
    /// Mean signed difference per channel (R, G, B), image minus reference, in levels (0 for an empty image).
    pub bias: [f64; 3],
}

impl Comparison {
    /// True when no channel of any pixel differs at all.
    pub fn identical(&self) -> bool {
        self.max_diff == 0
    }

    /// One line for a human: PSNR, RMSE, share of pixels off and the largest difference.
    pub fn summary(&self) -> String {
        let psnr = if self.psnr.is_infinite() {
            "PSNR inf (identical)".to_string()
        } else {
            format!("PSNR {:.2} dB", self.psnr)
        };
        format!(
            "{psnr}, RMSE {:.3} levels, {} of {} pixels off ({:.3}%), max diff {}",
            self.rmse,
            self.pixels_off,
            self.width as usize * self.height as usize,
            self.share_off * 100.0,
            self.max_diff
        )
    }

    /// One line for a human: the mean signed difference per channel.
    pub fn bias_summary(&self) -> String {
        bias_text(self.bias)
    }
}

/// `bias (image minus reference): R +0.125, G -0.500, B +0.000 levels`.
fn bias_text(bias: [f64; 3]) -> String {
    format!("bias (image minus reference): R {:+.3}, G {:+.3}, B {:+.3} levels", bias[0], bias[1], bias[2])
}

/// The mean of each channel's signed sum over `pixels` pixels (0 when there are none).
fn means(sums: [i64; 3], pixels: usize) -> [f64; 3] {
    sums.map(|s| if pixels == 0 { 0.0 } else { s as f64 / pixels as f64 })
}

/// Compares two row-major 8-bit RGB images of `width` x `height` pixels.
///
/// # Panics
/// When a slice is not `width * height * 3` bytes long: that is a caller's bug, not bad input
/// ([`compare_files`] checks sizes and reports them).
pub fn compare_rgb8(reference: &[u8], image: &[u8], width: u32, height: u32, threshold: u8) -> Comparison {
    let len = width as usize * height as usize * 3;
    assert_eq!(reference.len(), len, "reference is not {width}x{height} RGB");
    assert_eq!(image.len(), len, "image is not {width}x{height} RGB");
    let mut sum_sq = 0u64;
    let mut max_diff = 0u8;
    let mut pixels_off = 0usize;
    let mut signed = [0i64; 3];
    for (r, i) in reference.chunks_exact(3).zip(image.chunks_exact(3)) {
        let mut pixel_max = 0u8;
        for ((&a, &b), sum) in r.iter().zip(i).zip(&mut signed) {
            let d = a.abs_diff(b);
            sum_sq += u64::from(d) * u64::from(d);
            pixel_max = pixel_max.max(d);
            *sum += i64::from(b) - i64::from(a);
        }
        max_diff = max_diff.max(pixel_max);
        pixels_off += usize::from(pixel_max > threshold);
    }
    let pixels = len / 3;
    let mse = if len == 0 { 0.0 } else { sum_sq as f64 / len as f64 };
    Comparison {
        width,
        height,
        psnr: if mse == 0.0 { f64::INFINITY } else { 10.0 * (255.0 * 255.0 / mse).log10() },
        rmse: mse.sqrt(),
        max_diff,
        pixels_off,
        share_off: if pixels == 0 { 0.0 } else { pixels_off as f64 / pixels as f64 },
        bias: means(signed, pixels),
    }
}

/// The difference between the KxK-pixel block means of an image and those of its reference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlockComparison {
    /// Width in pixels of both images.
    pub width: u32,
    /// Height in pixels of both images.
    pub height: u32,
    /// The side K of a block, in pixels.
    pub block: u32,
    /// Blocks in the image, partial blocks at the right and bottom edges included.
    pub blocks: usize,
    /// Blocks whose mean differs by more than the threshold in a channel.
    pub blocks_off: usize,
    /// `blocks_off` divided by `blocks` (0 for an empty image).
    pub share_off: f64,
    /// The largest difference of a block's mean in any channel, in levels.
    pub max_diff: f64,
    /// Mean signed difference per channel (R, G, B) over all pixels, image minus reference, in levels
    /// (0 for an empty image); the same as [`Comparison::bias`].
    pub bias: [f64; 3],
}

impl BlockComparison {
    /// One line for a human: blocks off, their share and the largest block difference.
    pub fn summary(&self) -> String {
        format!(
            "{} of {} blocks of {k}x{k} pixels off ({:.3}%), max block diff {:.3} levels",
            self.blocks_off,
            self.blocks,
            self.share_off * 100.0,
            self.max_diff,
            k = self.block
        )
    }

    /// One line for a human: the mean signed difference per channel.
    pub fn bias_summary(&self) -> String {
        bias_text(self.bias)
    }
}

/// Compares the means of `block` x `block`-pixel blocks of two row-major 8-bit RGB images of `width` x
/// `height` pixels.
///
/// # Panics
/// Under the same conditions as [`compare_rgb8`], and when `block` is 0.
pub fn compare_blocks_rgb8(
    reference: &[u8],
    image: &[u8],
    width: u32,
    height: u32,
    block: u32,
    threshold: u8,
) -> BlockComparison {
    let len = width as usize * height as usize * 3;
    assert_eq!(reference.len(), len, "reference is not {width}x{height} RGB");
    assert_eq!(image.len(), len, "image is not {width}x{height} RGB");
    assert!(block > 0, "a block is at least 1 pixel wide");
    let (w, k) = (width as usize, block as usize);
    let mut sums = vec![[0i64; 3]; w.div_ceil(k)];
    let mut total = [0i64; 3];
    let (mut blocks, mut blocks_off, mut max_diff) = (0usize, 0usize, 0.0f64);
    let row = w * 3;
    // A band is one row of blocks; never more than the whole image, so that a huge K cannot overflow.
    let band = row * k.min(height as usize);
    // An empty image has rows of 0 bytes, which `chunks_exact` cannot take.
    if len > 0 {
        for (r_band, i_band) in reference.chunks(band).zip(image.chunks(band)) {
            band_sums(r_band, i_band, row, k, &mut sums);
            let rows = r_band.len() / row;
            for (bx, sum) in sums.iter().enumerate() {
                let pixels = (k.min(w - bx * k) * rows) as u64;
                let worst = sum.iter().map(|s| s.unsigned_abs()).max().unwrap_or(0);
                // mean > threshold compared in integers: a mean exactly at the threshold is never off by
                // a rounding error.
                blocks_off += usize::from(worst > u64::from(threshold) * pixels);
                max_diff = max_diff.max(worst as f64 / pixels as f64);
                for (t, s) in total.iter_mut().zip(sum) {
                    *t += s;
                }
            }
            blocks += sums.len();
        }
    }
    BlockComparison {
        width,
        height,
        block,
        blocks,
        blocks_off,
        share_off: if blocks == 0 { 0.0 } else { blocks_off as f64 / blocks as f64 },
        max_diff,
        bias: means(total, len / 3),
    }
}

/// Compares block means already in display levels ([`super::levels`]; high-dynamic-range images under
/// their reference's curve) of an image of `width` x `height` pixels: a block is off when a channel's mean
/// differs by strictly more than `threshold` levels.
///
/// # Panics
/// When the two have different blocks.
pub fn compare_block_levels(
    reference: &BlockLevels,
    image: &BlockLevels,
    width: u32,
    height: u32,
    threshold: u8,
) -> BlockComparison {
    assert_eq!(reference.pixels, image.pixels, "block means of images of different sizes or blocks");
    let worst: Vec<f64> = reference
        .means
        .iter()
        .zip(&image.means)
        .map(|(r, i)| (0..3).map(|c| (i[c] - r[c]).abs()).fold(0.0, f64::max))
        .collect();
    let blocks = worst.len();
    let blocks_off = worst.iter().filter(|&&d| d > f64::from(threshold)).count();
    let (r, i) = (reference.mean(), image.mean());
    BlockComparison {
        width,
        height,
        block: reference.block,
        blocks,
        blocks_off,
        share_off: if blocks == 0 { 0.0 } else { blocks_off as f64 / blocks as f64 },
        max_diff: worst.iter().copied().fold(0.0, f64::max),
        bias: [0, 1, 2].map(|c| i[c] - r[c]),
    }
}

/// The signed sums per channel (image minus reference) of the blocks of `k`-pixel width across one band of
/// rows of `row` bytes each.
fn band_sums(reference: &[u8], image: &[u8], row: usize, k: usize, sums: &mut [[i64; 3]]) {
    sums.fill([0; 3]);
    for (r_row, i_row) in reference.chunks_exact(row).zip(image.chunks_exact(row)) {
        for (x, (r, i)) in r_row.chunks_exact(3).zip(i_row.chunks_exact(3)).enumerate() {
            for ((sum, &a), &b) in sums[x / k].iter_mut().zip(r).zip(i) {
                *sum += i64::from(b) - i64::from(a);
            }
        }
    }
}

/// Reads both files as 8-bit RGB within `limits`: their common size and pixels; an error when they cannot
/// be read or differ in size.
fn read_pair(reference: &Path, image: &Path, limits: &ImageLimits) -> Result<(u32, u32, Vec<u8>, Vec<u8>)> {
    let (rw, rh, ref_px) = super::read(reference, limits)?;
    let (w, h, img_px) = super::read(image, limits)?;
    if (rw, rh) != (w, h) {
        return Err(Error::Invalid(format!(
            "{} is {w}x{h} but the reference {} is {rw}x{rh}",
            image.display(),
            reference.display()
        )));
    }
    Ok((w, h, ref_px, img_px))
}

/// Reads both files as 8-bit RGB within `limits` and compares them; an error when they cannot be read or
/// differ in size.
pub fn compare_files(reference: &Path, image: &Path, threshold: u8, limits: &ImageLimits) -> Result<Comparison> {
    let (w, h, ref_px, img_px) = read_pair(reference, image, limits)?;
    Ok(compare_rgb8(&ref_px, &img_px, w, h, threshold))
}

/// Reads both files as 8-bit RGB within `limits` and compares the means of their `block` x `block`-pixel
/// blocks; an error when they cannot be read or differ in size.
///
/// # Panics
/// When `block` is 0.
pub fn compare_blocks_files(
    reference: &Path,
    image: &Path,
    block: u32,
    threshold: u8,
    limits: &ImageLimits,
) -> Result<BlockComparison> {
    let (w, h, ref_px, img_px) = read_pair(reference, image, limits)?;
    Ok(compare_blocks_rgb8(&ref_px, &img_px, w, h, block, threshold))
}

/// A picture of where two 8-bit RGB images differ: the absolute difference per channel times `gain`, in
/// display units (a difference of `255 / gain` levels or more shows as full intensity once written as PNG).
///
/// # Panics
/// Under the same conditions as [`compare_rgb8`].
pub fn diff_image(reference: &[u8], image: &[u8], width: u32, height: u32, gain: f32) -> Film {
    let len = width as usize * height as usize * 3;
    assert_eq!(reference.len(), len, "reference is not {width}x{height} RGB");
    assert_eq!(image.len(), len, "image is not {width}x{height} RGB");
    let level = |a: u8, b: u8| f32::from(a.abs_diff(b)) * gain / 255.0;
    let pixels = reference
        .chunks_exact(3)
        .zip(image.chunks_exact(3))
        .map(|(r, i)| Color::new(level(r[0], i[0]), level(r[1], i[1]), level(r[2], i[2])))
        .collect();
    Film { width, height, pixels }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grey(v: u8, pixels: usize) -> Vec<u8> {
        vec![v; pixels * 3]
    }

    #[test]
    fn compare_identical_is_infinite_psnr_nothing_off() {
        let a = grey(100, 12);
        let c = compare_rgb8(&a, &a, 4, 3, 0);
        assert!(c.psnr.is_infinite() && c.psnr > 0.0);
        assert_eq!((c.rmse, c.max_diff, c.pixels_off, c.share_off), (0.0, 0, 0, 0.0));
        assert!(c.identical());
        assert!(c.summary().contains("PSNR inf"), "{}", c.summary());
    }

    #[test]
    fn compare_one_pixel_off_by_nine_counts_at_threshold_eight_only() {
        let a = grey(100, 10);
        let mut b = a.clone();
        b[3 * 7 + 1] = 109;
        let at8 = compare_rgb8(&a, &b, 5, 2, 8);
        assert_eq!((at8.pixels_off, at8.max_diff), (1, 9));
        assert!((at8.share_off - 0.1).abs() < 1e-12);
        let at9 = compare_rgb8(&a, &b, 5, 2, 9);
        assert_eq!((at9.pixels_off, at9.share_off), (0, 0.0));
        // One channel of 30 off by 9: MSE = 81 / 30.
        let mse: f64 = 81.0 / 30.0;
        assert!((at8.rmse - mse.sqrt()).abs() < 1e-12);
        assert!((at8.psnr - 10.0 * (65025.0 / mse).log10()).abs() < 1e-9);
    }

    #[test]
    fn compare_difference_is_symmetric_in_sign_except_bias() {
        let a = grey(10, 1);
        let b = grey(250, 1);
        let (ab, ba) = (compare_rgb8(&a, &b, 1, 1, 0), compare_rgb8(&b, &a, 1, 1, 0));
        assert_eq!((ab.bias, ba.bias), ([240.0; 3], [-240.0; 3]));
        assert_eq!(ab, Comparison { bias: [240.0; 3], ..ba });
        assert_eq!(ab.max_diff, 240);
    }

    #[test]
    fn compare_bias_is_mean_signed_difference_per_channel() {
        // Two pixels: R +5 and -1 (mean +2), G +0 and +1 (mean +0.5), B -4 and -4.
        let reference = [100, 100, 100, 50, 50, 50];
        let image = [105, 100, 96, 49, 51, 46];
        let c = compare_rgb8(&reference, &image, 2, 1, 8);
        assert_eq!(c.bias, [2.0, 0.5, -4.0]);
        assert_eq!(c.bias_summary(), "bias (image minus reference): R +2.000, G +0.500, B -4.000 levels");
        assert_eq!(c.pixels_off, 0);
    }

    #[test]
    fn compare_uniform_offset_is_its_bias() {
        let reference = grey(100, 6);
        let image: Vec<u8> = [103, 100, 98].repeat(6);
        assert_eq!(compare_rgb8(&reference, &image, 3, 2, 0).bias, [3.0, 0.0, -2.0]);
    }

    #[test]
    fn compare_empty_images_are_equal() {
        let c = compare_rgb8(&[], &[], 0, 0, 0);
        assert_eq!((c.pixels_off, c.share_off, c.bias), (0, 0.0, [0.0; 3]));
    }

    #[test]
    #[should_panic(expected = "not 2x2 RGB")]
    fn compare_wrong_slice_length_panics() {
        compare_rgb8(&grey(0, 4), &grey(0, 3), 2, 2, 0);
    }

    /// A `width` x `height` image whose pixel (x, y) is `f(x, y)`.
    fn image(width: u32, height: u32, f: impl Fn(u32, u32) -> [u8; 3]) -> Vec<u8> {
        (0..height).flat_map(|y| (0..width).map(move |x| (x, y))).flat_map(|(x, y)| f(x, y)).collect()
    }

    /// A reference that is not flat, so that a block mixing up pixels of the two images shows.
    fn gradient(x: u32, y: u32) -> [u8; 3] {
        [(100 + x + 4 * y) as u8, (50 + 3 * x) as u8, (200 - 5 * y) as u8]
    }

    /// `gradient` plus `delta(x, y)` per channel.
    fn shifted(width: u32, height: u32, delta: impl Fn(u32, u32) -> [i32; 3]) -> Vec<u8> {
        image(width, height, |x, y| {
            let (g, d) = (gradient(x, y), delta(x, y));
            [0, 1, 2].map(|c| (i32::from(g[c]) + d[c]) as u8)
        })
    }

    #[test]
    fn blocks_of_four_by_four_image_have_hand_computed_means() {
        let reference = image(4, 4, gradient);
        // Top right: R +10 everywhere (mean 10). Bottom left: G +12 in three pixels of four (mean 9).
        // Bottom right: B -8 everywhere (mean -8, at the threshold: not off). Top left: unchanged.
        let img = shifted(4, 4, |x, y| match (x / 2, y / 2) {
            (1, 0) => [10, 0, 0],
            (0, 1) if (x, y) != (1, 3) => [0, 12, 0],
            (1, 1) => [0, 0, -8],
            _ => [0; 3],
        });
        let c = compare_blocks_rgb8(&reference, &img, 4, 4, 2, 8);
        assert_eq!((c.blocks, c.blocks_off, c.share_off, c.max_diff), (4, 2, 0.5, 10.0));
        // Sums over 16 pixels: R 4 * 10, G 3 * 12, B 4 * -8.
        assert_eq!(c.bias, [2.5, 2.25, -2.0]);
        let at9 = compare_blocks_rgb8(&reference, &img, 4, 4, 2, 9);
        assert_eq!((at9.blocks_off, at9.share_off), (1, 0.25));
        assert_eq!(compare_blocks_rgb8(&reference, &img, 4, 4, 2, 10).blocks_off, 0);
        assert_eq!(compare_rgb8(&reference, &img, 4, 4, 8).pixels_off, 7);
    }

    #[test]
    fn blocks_cancel_noise_that_pixels_count() {
        // A checkerboard of +-20 in every channel: every pixel off, every 2x2 block mean exact.
        let noise = |x: u32, y: u32| if (x + y).is_multiple_of(2) { [20; 3] } else { [-20; 3] };
        let (reference, img) = (image(4, 4, gradient), shifted(4, 4, noise));
        let pixels = compare_rgb8(&reference, &img, 4, 4, 8);
        assert_eq!((pixels.pixels_off, pixels.max_diff, pixels.bias), (16, 20, [0.0; 3]));
        let blocks = compare_blocks_rgb8(&reference, &img, 4, 4, 2, 8);
        assert_eq!((blocks.blocks, blocks.blocks_off, blocks.max_diff, blocks.bias), (4, 0, 0.0, [0.0; 3]));
        // 3x3 blocks of a 4x4 image: the 3x3 block has five + and four - (mean 20/9), the 1x3 and 3x1 edge
        // blocks two - and one + (mean -20/3), the 1x1 corner one + (mean 20): only the corner is off.
        let odd = compare_blocks_rgb8(&reference, &img, 4, 4, 3, 8);
        assert_eq!((odd.blocks, odd.blocks_off, odd.max_diff), (4, 1, 20.0));
        assert_eq!(compare_blocks_rgb8(&reference, &img, 4, 4, 3, 6).blocks_off, 3);
    }

    #[test]
    fn blocks_at_the_edges_average_the_pixels_they_have() {
        // 5x3 pixels in 2x2 blocks: columns of width 2, 2, 1 and rows of height 2, 1.
        let img = shifted(5, 3, |x, y| match (x, y) {
            (4, 0) => [9, 0, 0],  // the 1x2 block at the right: mean 4.5, not off
            (2, 2) => [0, 18, 0], // the 2x1 block at the bottom: mean 9, off
            (4, 2) => [0, 0, -9], // the 1x1 corner: mean -9, off
            _ => [0; 3],
        });
        let c = compare_blocks_rgb8(&image(5, 3, gradient), &img, 5, 3, 2, 8);
        assert_eq!((c.blocks, c.blocks_off, c.max_diff), (6, 2, 9.0));
        assert_eq!(c.bias, [9.0 / 15.0, 18.0 / 15.0, -9.0 / 15.0]);
    }

    #[test]
    fn blocks_uniform_offset_is_the_bias_and_the_block_difference() {
        let reference = image(6, 5, gradient);
        let img = shifted(6, 5, |_, _| [3, 0, -2]);
        for k in [1, 2, 4, 7] {
            let c = compare_blocks_rgb8(&reference, &img, 6, 5, k, 2);
            assert_eq!((c.bias, c.max_diff, c.blocks_off, c.share_off), ([3.0, 0.0, -2.0], 3.0, c.blocks, 1.0));
            assert_eq!(compare_blocks_rgb8(&reference, &img, 6, 5, k, 3).blocks_off, 0);
        }
        assert_eq!(compare_rgb8(&reference, &img, 6, 5, 2).bias, [3.0, 0.0, -2.0]);
    }

    #[test]
    fn blocks_of_one_pixel_follow_the_pixel_rule() {
        let mut seed = 12345u32;
        let mut next = || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (seed >> 24) as u8
        };
        let reference: Vec<u8> = (0..7 * 5 * 3).map(|_| next()).collect();
        let img: Vec<u8> =
            reference.iter().map(|&v| v.saturating_add(next() % 32).saturating_sub(next() % 32)).collect();
        let mut counts = Vec::new();
        for threshold in [0, 5, 12, 20, 40] {
            let (p, b) = (
                compare_rgb8(&reference, &img, 7, 5, threshold),
                compare_blocks_rgb8(&reference, &img, 7, 5, 1, threshold),
            );
            assert_eq!((b.blocks, b.blocks_off, b.share_off), (35, p.pixels_off, p.share_off), "{threshold}");
            assert_eq!((b.max_diff, b.bias), (f64::from(p.max_diff), p.bias), "{threshold}");
            counts.push(p.pixels_off);
        }
        assert!(counts.windows(2).all(|w| w[0] > w[1]), "the thresholds do not tell the pixels apart: {counts:?}");
    }

    #[test]
    fn blocks_larger_than_the_image_are_one_block_of_the_whole_image() {
        let reference = image(3, 2, gradient);
        let img = shifted(3, 2, |x, _| [0, 3 * x as i32, -6]);
        let c = compare_blocks_rgb8(&reference, &img, 3, 2, u32::MAX, 2);
        // G's mean is (0 + 3 + 6) / 3 = 3, B's is -6.
        assert_eq!((c.blocks, c.blocks_off, c.max_diff, c.bias), (1, 1, 6.0, [0.0, 3.0, -6.0]));
    }

    #[test]
    fn blocks_of_an_empty_image_are_none() {
        let c = compare_blocks_rgb8(&[], &[], 0, 0, 4, 0);
        assert_eq!((c.blocks, c.blocks_off, c.share_off, c.max_diff, c.bias), (0, 0, 0.0, 0.0, [0.0; 3]));
        assert_eq!(compare_blocks_rgb8(&[], &[], 5, 0, 2, 0).blocks, 0);
    }

    #[test]
    #[should_panic(expected = "a block is at least 1 pixel wide")]
    fn blocks_of_zero_pixels_panic() {
        compare_blocks_rgb8(&grey(0, 4), &grey(0, 4), 2, 2, 0, 0);
    }

    #[test]
    fn blocks_summary_text() {
        let img = shifted(4, 4, |x, y| if (x, y) == (0, 0) { [-40, 0, 0] } else { [0; 3] });
        let c = compare_blocks_rgb8(&image(4, 4, gradient), &img, 4, 4, 2, 8);
        assert_eq!(c.summary(), "1 of 4 blocks of 2x2 pixels off (25.000%), max block diff 10.000 levels");
        assert_eq!(c.bias_summary(), "bias (image minus reference): R -2.500, G +0.000, B +0.000 levels");
    }

    #[test]
    fn diff_image_amplifies_absolute_difference() {
        let film = diff_image(&[10, 20, 30], &[20, 10, 30], 1, 1, 10.0);
        let expected = 100.0 / 255.0;
        assert!((film.pixels[0] - Color::new(expected, expected, 0.0)).abs().max_element() < 1e-6);
    }
}
