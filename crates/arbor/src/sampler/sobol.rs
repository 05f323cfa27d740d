//! The points of [`super::SamplerKind::Sobol`]: the first two dimensions of Sobol's sequence (a
//! (0,2)-sequence in base 2: every `2^m` consecutive points from a multiple of `2^m` form a (0,m,2)-net,
//! one point in each of the `2^m` boxes of every shape `2^-a x 2^-(m-a)`), randomised by Owen's nested
//! uniform scrambling in the hashed form of Burley 2020 ("Practical Hash-based Owen Scrambling", JCGT
//! 9(4), after Laine and Karras 2011). The padding over dimensions is the sampler's: each dimension
//! takes the pixel's samples in its own random order ([`super::permute`]) and scrambles with its own
//! seed, as pbrt-v4's padded Sobol sampler does.
//!
//! Invariants: a scrambled point is uniform on `[0, 1)^2` on its own (so every estimate stays unbiased),
//! and scrambling keeps the net (the tests check both). Written by hand: it is a few integer operations
//! per number (four lookups in a 4 KiB table and two hashes per 2D point) on the path tracer's every
//! vertex, where a general low-discrepancy crate's tables and dispatch would cost more than the point.

use super::unit_float;

/// Sobol's direction numbers of his second dimension (primitive polynomial `x + 1`): `v_0 = 2^31`,
/// `v_i = v_(i-1) ^ (v_(i-1) >> 1)`. His first dimension is the bit reversal of the index (van der Corput).
const DIRECTIONS: [u32; 32] = {
    let mut v = [0u32; 32];
    v[0] = 1 << 31;
    let mut i = 1;
    while i < 32 {
        v[i] = v[i - 1] ^ (v[i - 1] >> 1);
        i += 1;
    }
    v
};

/// The second dimension's point of every byte of an index, bit-reversed (the scramble works on reversed
/// fractions): `BYTES[j][b]` is the XOR of `DIRECTIONS[8j + i]` over the bits `i` of `b`, reversed. Four
/// lookups instead of a branch per bit of the index (a loop over its bits mispredicted).
static BYTES: [[u32; 256]; 4] = {
    let mut t = [[0u32; 256]; 4];
    let mut j = 0;
    while j < 4 {
        let mut b = 0;
        while b < 256 {
            let mut y = 0u32;
            let mut i = 0;
            while i < 8 {
                if b >> i & 1 != 0 {
                    y ^= DIRECTIONS[8 * j + i];
                }
                i += 1;
            }
            t[j][b] = y.reverse_bits();
            b += 1;
        }
        j += 1;
    }
    t
};

/// Point `index` of Sobol's sequence in its first two dimensions, Owen-scrambled by `seed` (one seed per
/// axis, its two halves), in `[0, 1)^2`.
#[inline]
pub fn point_2d(index: u32, seed: u64) -> [f32; 2] {
    // Van der Corput's fraction reversed is the index itself.
    let (x, y) = (index, second_dimension_reversed(index));
    [unit_float(scramble_reversed(x, seed as u32)), unit_float(scramble_reversed(y, (seed >> 32) as u32))]
}

/// Sobol's second dimension of point `index`, bit-reversed, from the byte tables.
#[inline]
fn second_dimension_reversed(index: u32) -> u32 {
    let [a, b, c, d] = index.to_le_bytes();
    BYTES[0][a as usize] ^ BYTES[1][b as usize] ^ BYTES[2][c as usize] ^ BYTES[3][d as usize]
}

/// Point `index` of van der Corput's sequence (Sobol's first dimension), Owen-scrambled by `seed`, in
/// `[0, 1)`.
#[inline]
pub fn point_1d(index: u32, seed: u32) -> f32 {
    unit_float(scramble_reversed(index, seed))
}

/// Owen's nested uniform scrambling of a 32-bit fraction given bit-reversed (`x`'s least significant
/// bit its first binary digit), returned in the usual order: each digit is flipped or not by a hash of
/// the digits before it and `seed`. Burley's form: reversed, a digit's flip depends only on the bits
/// below it, which is what a multiplication by an even constant gives (the Laine-Karras hash; his
/// constants).
#[inline]
fn scramble_reversed(mut v: u32, seed: u32) -> u32 {
    v = v.wrapping_add(seed);
    v ^= v.wrapping_mul(0x6c50_b47c);
    v ^= v.wrapping_mul(0xb82f_1e52);
    v ^= v.wrapping_mul(0xc7af_e638);
    v ^= v.wrapping_mul(0x8d22_f6e6);
    v.reverse_bits()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sobol's second dimension of point `i` by the definition: the XOR of the direction numbers of its
    /// set bits.
    fn bit_loop(i: u32) -> u32 {
        (0..32).filter(|b| i >> b & 1 != 0).fold(0, |y, b| y ^ DIRECTIONS[b])
    }

    /// Whether `points` (2^m of them) put one point in every box `2^-a x 2^-(m-a)`, for every `a`.
    fn is_net(points: &[[f32; 2]]) -> bool {
        let m = points.len().trailing_zeros();
        (0..=m).all(|a| {
            let (nx, ny) = (1u32 << a, 1u32 << (m - a));
            let mut seen = vec![false; points.len()];
            points.iter().all(|p| {
                let cell = ((p[1] * ny as f32) as u32 * nx + (p[0] * nx as f32) as u32) as usize;
                !std::mem::replace(&mut seen[cell], true)
            })
        })
    }

    #[test]
    fn sobol_points_form_nets_scrambled_or_not() {
        for m in 0..=8 {
            let n = 1u32 << m;
            for seed in [0u64, 1, 0x9e37_79b9_7f4a_7c15, u64::MAX] {
                // Any aligned block of 2^m consecutive points is a net, not only the first.
                for start in [0, n, 5 * n] {
                    let pts: Vec<[f32; 2]> = (start..start + n).map(|i| point_2d(i, seed)).collect();
                    assert!(is_net(&pts), "m {m} seed {seed:x} start {start}");
                    let mut xs: Vec<u32> =
                        (start..start + n).map(|i| (point_1d(i, seed as u32) * n as f32) as u32).collect();
                    xs.sort_unstable();
                    assert_eq!(xs, (0..n).collect::<Vec<_>>(), "1D, m {m}");
                }
            }
        }
        // The unscrambled points are Sobol's own: (0, 0), (1/2, 1/2), (1/4, 3/4), (3/4, 1/4).
        let raw: Vec<[u32; 2]> = (0..4u32).map(|i| [i.reverse_bits() >> 30, bit_loop(i) >> 30]).collect();
        assert_eq!(raw, [[0, 0], [2, 2], [1, 3], [3, 1]]);
        // The byte tables give the bit loop's point for every index.
        for i in (0..5000u32).chain([0x1234_5678, u32::MAX, 1 << 31]) {
            assert_eq!(second_dimension_reversed(i), bit_loop(i).reverse_bits(), "{i}");
        }
    }

    #[test]
    fn sobol_scrambled_points_are_uniform_and_differ_by_seed() {
        // Over seeds, one point is uniform: its mean 1/2 and its second moment 1/3 on each axis, and the
        // axes uncorrelated.
        let k = 20_000u64;
        let (mut m1, mut m2, mut cross) = ([0.0f64; 2], [0.0f64; 2], 0.0f64);
        for s in 0..k {
            let seed = s.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ (s << 17);
            let p = point_2d(3, super::super::mix(seed));
            for a in 0..2 {
                m1[a] += p[a] as f64 / k as f64;
                m2[a] += (p[a] as f64).powi(2) / k as f64;
            }
            cross += (p[0] as f64 - 0.5) * (p[1] as f64 - 0.5) / k as f64;
        }
        for a in 0..2 {
            assert!((m1[a] - 0.5).abs() < 0.01 && (m2[a] - 1.0 / 3.0).abs() < 0.01, "axis {a}: {m1:?} {m2:?}");
        }
        assert!(cross.abs() < 0.005, "{cross}");
        assert_ne!(point_2d(5, 1), point_2d(5, 2));
        assert!((0..1000).all(|i| point_2d(i, 7).iter().all(|v| (0.0..1.0).contains(v))));
    }
}
