//! Deterministic sampling: every pixel sample draws from its own small random stream, seeded by the
//! render's seed, the pixel and the sample index only, so an image is the same for any thread count,
//! tile order or split into sample ranges, and another seed gives independent noise.

use crate::math::Vec2;

/// A PCG32 stream (O'Neill 2014): tiny state, good statistics, cheap to seed per sample.
#[derive(Debug, Clone)]
pub struct Rng {
    state: u64,
    inc: u64,
}

impl Rng {
    /// The stream for sample `sample` of pixel `(x, y)` under `seed`.
    pub fn for_sample(x: u32, y: u32, sample: u32, seed: u64) -> Rng {
        let pixel = ((y as u64) << 32) | x as u64;
        // `mix(0)` is 0: seed 0 keeps the streams Arbor has always drawn (and the images they made).
        let mut rng = Rng { state: 0, inc: ((mix(pixel) ^ mix(seed)) << 1) | 1 };
        rng.next_u32();
        rng.state = rng.state.wrapping_add(mix(sample as u64 ^ 0x9e37_79b9_7f4a_7c15));
        rng.next_u32();
        rng
    }

    /// The next 32 random bits.
    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(self.inc);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        xorshifted.rotate_right((old >> 59) as u32)
    }

    /// A float uniform in `[0, 1)`.
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
    }

    /// Two floats uniform in `[0, 1)`.
    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        Vec2::new(self.next_f32(), self.next_f32())
    }
}

/// SplitMix64's finaliser: spreads neighbouring seeds over the whole state space.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The image-plane offset in `[0, 1)²` of sample `k` of `n`: the pixel centre for one sample, otherwise
/// a jittered point in cell `k` of a `cols x rows` grid (`cols = ceil(sqrt(n))`).
pub fn pixel_offset(k: u32, n: u32, rng: &mut Rng) -> Vec2 {
    if n <= 1 {
        return Vec2::splat(0.5);
    }
    let cols = (n as f32).sqrt().ceil() as u32;
    let rows = n.div_ceil(cols);
    let cell = Vec2::new((k % cols) as f32, (k / cols) as f32);
    (cell + rng.next_2d()) / Vec2::new(cols as f32, rows as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first value of pixel (3, 4)'s sample 0 before seeds existed.
    const SEED0_FIRST: u32 = 3_548_415_727;

    #[test]
    fn sampler_streams_repeat_and_differ() {
        let a: Vec<u32> = (0..4).map(|_| Rng::for_sample(3, 4, 0, 0).next_u32()).collect();
        assert!(a.windows(2).all(|w| w[0] == w[1]));
        assert_ne!(Rng::for_sample(3, 4, 0, 0).next_u32(), Rng::for_sample(4, 3, 0, 0).next_u32());
        assert_ne!(Rng::for_sample(3, 4, 0, 0).next_u32(), Rng::for_sample(3, 4, 1, 0).next_u32());
        assert_ne!(Rng::for_sample(3, 4, 0, 0).next_u32(), Rng::for_sample(3, 4, 0, 1).next_u32());
        assert_ne!(Rng::for_sample(3, 4, 0, 1).next_u32(), Rng::for_sample(3, 4, 0, 2).next_u32());
        // Seed 0 is the stream of the original (seedless) sampler, pinned by its first value.
        assert_eq!(Rng::for_sample(3, 4, 0, 0).next_u32(), SEED0_FIRST);
    }

    #[test]
    fn sampler_offsets_cover_their_strata() {
        let mut rng = Rng::for_sample(0, 0, 0, 0);
        assert_eq!(pixel_offset(0, 1, &mut rng), Vec2::splat(0.5));
        for k in 0..16 {
            let o = pixel_offset(k, 16, &mut rng);
            let cell = (o * 4.0).floor();
            assert_eq!(cell, Vec2::new((k % 4) as f32, (k / 4) as f32));
        }
    }

    #[test]
    fn sampler_floats_are_in_unit_interval_with_sane_mean() {
        let mut rng = Rng::for_sample(7, 7, 7, 0);
        let xs: Vec<f32> = (0..10_000).map(|_| rng.next_f32()).collect();
        assert!(xs.iter().all(|&x| (0.0..1.0).contains(&x)));
        let mean = xs.iter().sum::<f32>() / xs.len() as f32;
        assert!((mean - 0.5).abs() < 0.02);
    }
}
