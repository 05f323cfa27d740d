//! Comparing a render with a noisy reference (a path-traced one), as project issue 17 defines it: both
//! images are signal plus noise, and two official renders of one scene differ by 5-18 levels even in
//! 16x16 block means, so no fixed threshold separates a wrong render from an unlucky one. The noise is
//! measured instead, from two renders at the reference's samples with different seeds; a render at four
//! times the samples (less noise of its own) must then be as close to the reference as those two are to
//! each other, plus [`NOISE_MARGIN`] levels, with every channel's mean signed difference within
//! [`BIAS_LIMIT`] levels. Everything is on the means of KxK-pixel blocks of 8-bit images (edge blocks over
//! the pixels they have).

/// Levels the converged render may be farther from the reference than the seeds from each other.
pub const NOISE_MARGIN: f64 = 1.0;
/// Largest mean signed difference per channel, in levels.
pub const BIAS_LIMIT: f64 = 2.0;

/// The outcome of [`compare_noisy_rgb8`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoisyComparison {
    /// Block side in pixels.
    pub block: u32,
    /// Mean absolute difference of block means, converged render against the reference.
    pub mad: f64,
    /// Mean absolute difference of block means between the two seeds' renders: the noise.
    pub noise: f64,
    /// Mean signed difference per channel, converged render minus reference.
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
            "{k}x{k} blocks: converged vs reference {:.2} levels, seed vs seed {:.2} (limit {:.2}); bias {:+.2} \
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

/// The means of the `block` x `block`-pixel blocks of a row-major 8-bit RGB image, row by row.
///
/// # Panics
/// When `rgb` is not `3 * width * height` bytes or `block` is 0.
pub fn block_means(rgb: &[u8], width: u32, height: u32, block: u32) -> Vec<[f64; 3]> {
    assert_eq!(rgb.len(), 3 * width as usize * height as usize, "image is not {width}x{height} RGB");
    assert!(block > 0, "a block is at least 1 pixel wide");
    let (w, h, k) = (width as usize, height as usize, block as usize);
    let (bw, bh) = (w.div_ceil(k), h.div_ceil(k));
    let mut sums = vec![[0u64; 4]; bw * bh];
    for y in 0..h {
        for x in 0..w {
            let s = &mut sums[(y / k) * bw + x / k];
            for c in 0..3 {
                s[c] += u64::from(rgb[3 * (y * w + x) + c]);
            }
            s[3] += 1;
        }
    }
    sums.iter().map(|s| [0, 1, 2].map(|c| s[c] as f64 / s[3] as f64)).collect()
}

/// Compares `converged` (four times the reference's samples) with `reference`, against the noise between
/// `seed_a` and `seed_b` (the reference's samples, two seeds); all row-major 8-bit RGB of one size.
///
/// # Panics
/// When an image is not `3 * width * height` bytes or `block` is 0.
pub fn compare_noisy_rgb8(
    reference: &[u8],
    converged: &[u8],
    seed_a: &[u8],
    seed_b: &[u8],
    width: u32,
    height: u32,
    block: u32,
) -> NoisyComparison {
    let means = |img: &[u8]| block_means(img, width, height, block);
    let (r, c, a, b) = (means(reference), means(converged), means(seed_a), means(seed_b));
    let mad = |x: &[[f64; 3]], y: &[[f64; 3]]| {
        let n = (3 * x.len()).max(1) as f64;
        x.iter().zip(y).flat_map(|(p, q)| (0..3).map(move |i| (p[i] - q[i]).abs())).sum::<f64>() / n
    };
    // The bias is over pixels, so weigh each block by its pixel count: exact means of the whole images.
    let total = |img: &[u8]| {
        let mut t = [0u64; 3];
        for px in img.chunks_exact(3) {
            (0..3).for_each(|i| t[i] += u64::from(px[i]));
        }
        t
    };
    let pixels = (width as f64 * height as f64).max(1.0);
    let (tc, tr) = (total(converged), total(reference));
    let bias = [0, 1, 2].map(|i| (tc[i] as f64 - tr[i] as f64) / pixels);
    NoisyComparison { block, mad: mad(&c, &r), noise: mad(&a, &b), bias }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noisy_block_means_cover_edge_blocks_with_the_pixels_they_have() {
        // 3x2 pixels, blocks of 2: a 2x2 block and a 1x2 one.
        let rgb: Vec<u8> = [10u8, 20, 30, 40, 50, 60].iter().flat_map(|&v| [v, 0, 255]).collect();
        let m = block_means(&rgb, 3, 2, 2);
        assert_eq!(m, vec![[(10.0 + 20.0 + 40.0 + 50.0) / 4.0, 0.0, 255.0], [45.0, 0.0, 255.0]]);
    }

    #[test]
    fn noisy_rule_passes_within_the_seed_noise_and_fails_on_a_bias() {
        let (w, h) = (32u32, 32u32);
        let n = (w * h) as usize;
        // A signal of 100, noise of ±6 in alternating blocks between the seeds.
        let flat = |v: u8| vec![v; 3 * n];
        let reference = flat(100);
        let (a, b) = (flat(103), flat(97));
        let ok = compare_noisy_rgb8(&reference, &flat(101), &a, &b, w, h, 16);
        assert_eq!((ok.mad, ok.noise, ok.bias), (1.0, 6.0, [1.0; 3]));
        assert!(ok.passes(), "{}", ok.summary());
        // Close to the noise but biased by 3 levels everywhere.
        let biased = compare_noisy_rgb8(&reference, &flat(103), &a, &b, w, h, 16);
        assert!(!biased.passes(), "{}", biased.summary());
        // Seeds that agree leave only the margin.
        let tight = compare_noisy_rgb8(&reference, &flat(102), &reference, &reference, w, h, 16);
        assert!(!tight.passes() && tight.summary().ends_with("FAIL"), "{}", tight.summary());
    }
}
