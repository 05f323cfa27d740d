//! Exact per-pixel sample sums: each sample's radiance is rounded once to a 64.64 fixed-point integer
//! and the integers are added, so a pixel's sum does not depend on how its samples were grouped.
//!
//! Why: a farm renders a pixel's samples in ranges on different machines and `arbor merge` adds the
//! ranges' sums. Float addition is not associative (`(a + b) + c != a + (b + c)` in general), so a
//! merged image would differ from the single-process one in the last bits. Integer addition is
//! associative: the single-process render and any merge of sample ranges give the same sum, hence
//! the same `f32` pixel and the same bytes in every output format.
//!
//! Invariants: a sample is clamped to `±2^62` and NaN counts as 0 before rounding (truncation towards
//! zero below `2^-64`), so at most 2^34 samples (the scene limit) can never overflow an `i128`. Cost:
//! one shift of the float's significand per channel and sample, negligible next to tracing the sample's
//! rays.

use crate::math::Color;

/// `2^64`: one unit of the fixed-point sum is `2^-64`.
const ONE: f64 = 18_446_744_073_709_551_616.0;
/// The largest magnitude a single sample channel is kept at.
const CLAMP: f32 = 4_611_686_018_427_387_904.0; // 2^62

/// The exact sum of some samples of one pixel, per channel, in units of `2^-64`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SampleSum(pub [i128; 3]);

impl SampleSum {
    /// Adds one sample.
    #[inline]
    pub fn add_sample(&mut self, c: Color) {
        for (s, v) in self.0.iter_mut().zip(c.to_array()) {
            *s += to_fixed(v);
        }
    }

    /// Adds another sum of the same pixel (other samples).
    #[inline]
    pub fn add(&mut self, other: &SampleSum) {
        for (s, o) in self.0.iter_mut().zip(other.0) {
            *s = s.wrapping_add(o);
        }
    }

    /// The pixel value for `spp` samples in all: the sum rounded to `f32`, times `scale / spp`.
    #[inline]
    pub fn value(&self, scale: f32, spp: u32) -> Color {
        let [r, g, b] = self.0.map(to_f32);
        Color::new(r, g, b) * (scale / spp.max(1) as f32)
    }
}

/// One channel of one sample in fixed point: `v · 2^64` truncated towards zero, as
/// `(v as f64 * 2^64) as i128` gives it, from the float's own bits (the 24-bit significand shifted by
/// the exponent), without the library's generic float-to-`i128` conversion.
#[inline]
fn to_fixed(v: f32) -> i128 {
    let v = if v.is_nan() { 0.0 } else { v.clamp(-CLAMP, CLAMP) };
    let bits = v.to_bits();
    let biased = ((bits >> 23) & 0xff) as i32;
    let significand = (bits & 0x7f_ffff) | if biased == 0 { 0 } else { 0x80_0000 };
    // |v| = significand · 2^(e - 150), e the biased exponent (1 for subnormals); times 2^64. At most
    // 2^62 · 2^64 < 2^127 after the clamp.
    let shift = biased.max(1) - 86;
    let magnitude = if shift >= 0 {
        (significand as i128) << shift
    } else if shift > -32 {
        (significand >> -shift) as i128
    } else {
        0
    };
    if bits >> 31 == 0 {
        magnitude
    } else {
        -magnitude
    }
}

/// A fixed-point sum rounded to `f32` (through `f64`: deterministic, which is all that matters here).
#[inline]
fn to_f32(s: i128) -> f32 {
    (s as f64 / ONE) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accum_sums_do_not_depend_on_grouping() {
        let samples = [0.1f32, 3.0e-7, 1234.5, 0.3333, 7.0e-12, 0.9];
        let mut whole = SampleSum::default();
        samples.iter().for_each(|&v| whole.add_sample(Color::splat(v)));
        for split in 0..=samples.len() {
            let (mut a, mut b) = (SampleSum::default(), SampleSum::default());
            samples[..split].iter().for_each(|&v| a.add_sample(Color::splat(v)));
            samples[split..].iter().for_each(|&v| b.add_sample(Color::splat(v)));
            b.add(&a);
            assert_eq!(b, whole);
        }
    }

    #[test]
    fn accum_to_fixed_truncates_as_the_float_conversion_does() {
        let reference = |v: f32| {
            let v = if v.is_nan() { 0.0 } else { v.clamp(-CLAMP, CLAMP) };
            (v as f64 * ONE) as i128
        };
        let mut special =
            vec![0.0, -0.0, 1.0, -1.0, 0.5, 1.5, 3.0e-7, f32::MIN_POSITIVE, -f32::MIN_POSITIVE, f32::EPSILON];
        special.extend([CLAMP, -CLAMP, f32::MAX, f32::MIN, f32::INFINITY, f32::NEG_INFINITY, f32::NAN]);
        // 2^-64 and its neighbours: the smallest values that do not truncate to zero.
        let unit = (1.0f64 / ONE) as f32;
        special.extend([unit, unit.next_up(), unit.next_down(), -unit, -unit.next_down(), 1.0e-40, -1.0e-40]);
        for v in special {
            assert_eq!(to_fixed(v), reference(v), "{v:e}");
        }
        // Every exponent, and a spread of significands and signs (a Weyl sequence over the bit patterns).
        let mut bits = 0u32;
        for _ in 0..2_000_000 {
            bits = bits.wrapping_add(0x9e37_79b9);
            let v = f32::from_bits(bits);
            assert_eq!(to_fixed(v), reference(v), "{v:e} ({bits:#x})");
        }
    }

    #[test]
    fn accum_one_sample_is_exact_and_nan_is_zero() {
        let mut s = SampleSum::default();
        s.add_sample(Color::new(0.75, 1.0e-3, 5.0));
        assert_eq!(s.value(1.0, 1), Color::new(0.75, 1.0e-3, 5.0));
        let mut n = SampleSum::default();
        n.add_sample(Color::new(f32::NAN, f32::INFINITY, -f32::INFINITY));
        assert_eq!(n.value(1.0, 1), Color::new(0.0, CLAMP, -CLAMP));
    }
}
