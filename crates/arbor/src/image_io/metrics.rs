//! How far an image is from its reference, in 8-bit levels: PSNR, RMSE, the largest channel difference,
//! the share of pixels that differ by more than a threshold, and the bias (the mean signed difference per
//! channel, image minus reference).
//!
//! All statistics are over the three channels of every pixel (alpha is never compared: [`compare_files`]
//! reads both images with [`read_rgb8`](super::read_rgb8)). PSNR uses a peak of 255:
//! `10 log10(255^2 / MSE)`, infinite for identical images. A pixel is "off" when any of its channels
//! differs by strictly more than the threshold, so threshold 0 counts every difference. Cost: one pass.

use std::path::Path;

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

/// Reads both files as 8-bit RGB and compares them; an error when they cannot be read or differ in size.
pub fn compare_files(reference: &Path, image: &Path, threshold: u8) -> Result<Comparison> {
    let (rw, rh, ref_px) = super::read_rgb8(reference)?;
    let (w, h, img_px) = super::read_rgb8(image)?;
    if (rw, rh) != (w, h) {
        return Err(Error::Invalid(format!(
            "{} is {w}x{h} but the reference {} is {rw}x{rh}",
            image.display(),
            reference.display()
        )));
    }
    Ok(compare_rgb8(&ref_px, &img_px, w, h, threshold))
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

    #[test]
    fn diff_image_amplifies_absolute_difference() {
        let film = diff_image(&[10, 20, 30], &[20, 10, 30], 1, 1, 10.0);
        let expected = 100.0 / 255.0;
        assert!((film.pixels[0] - Color::new(expected, expected, 0.0)).abs().max_element() < 1e-6);
    }
}
