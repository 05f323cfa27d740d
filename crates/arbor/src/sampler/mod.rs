//! Deterministic sampling: every pixel sample draws from its own small random stream, seeded by the
//! render's seed, the pixel and the sample index only, so an image is the same for any thread count,
//! tile order or split into sample ranges, and another seed gives independent noise.

use crate::math::Vec2;

pub mod sobol;

/// A PCG32 stream (O'Neill 2014): tiny state, good statistics, cheap to seed per sample.
#[derive(Debug, Clone)]
pub struct Rng {
    state: u64,
    inc: u64,
}

impl Rng {
    /// The stream for sample `sample` of pixel `(x, y)` under `seed`.
    pub fn for_sample(x: u32, y: u32, sample: u32, seed: u64) -> Rng {
        let pixel = pixel_bits(x, y);
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
        unit_float(self.next_u32())
    }

    /// Two floats uniform in `[0, 1)`.
    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        Vec2::new(self.next_f32(), self.next_f32())
    }
}

/// 32 random bits (or a 32-bit binary fraction) as a float in `[0, 1)`: the top 24 bits, exact, never
/// rounded up to 1.
#[inline]
fn unit_float(bits: u32) -> f32 {
    (bits >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// Pixel `(x, y)` as one 64-bit word, the input of the per-pixel hashes.
fn pixel_bits(x: u32, y: u32) -> u64 {
    ((y as u64) << 32) | x as u64
}

/// SplitMix64's finaliser: spreads neighbouring seeds over the whole state space.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The stratification of `n` samples per pixel, worked out once per render. Sample `k`'s image-plane
/// offset in `[0, 1)²` ([`Strata::offset`]) is the pixel centre for one sample, otherwise a jittered
/// point in cell `k` of a `cols x rows` grid (`cols = ceil(sqrt(n))`, `rows = ceil(n / cols)`). When `n`
/// does not fill that grid (`--spp 10`: 4 x 3 cells for 10 samples), the `rows` rows hold `n / rows` or
/// one more samples each and are as tall as their share of the samples, so that every cell still covers
/// `1/n` of the pixel and the estimate stays unbiased.
#[derive(Debug, Clone, Copy)]
pub struct Strata {
    n: u32,
    cols: u32,
    rows: u32,
}

impl Strata {
    /// The grid of `n` samples per pixel.
    pub fn new(n: u32) -> Self {
        let cols = if n <= 1 { 1 } else { (n as f32).sqrt().ceil() as u32 };
        Strata { n, cols, rows: n.div_ceil(cols) }
    }

    /// The offset of sample `k` (see [`Strata`]). Always inlined: out of line, the padded dimensions'
    /// every draw paid a call for it.
    #[inline(always)]
    pub fn offset(&self, k: u32, rng: &mut Rng) -> Vec2 {
        let Strata { n, cols, rows } = *self;
        if n <= 1 {
            return Vec2::splat(0.5);
        }
        if cols * rows == n {
            let cell = Vec2::new((k % cols) as f32, (k / cols) as f32);
            return (cell + rng.next_2d()) / Vec2::new(cols as f32, rows as f32);
        }
        // The first `n % rows` rows hold one sample more than the others.
        let (short, long) = (n / rows, n / rows + 1);
        let long_rows = n % rows;
        let (row, col, len) = match k.checked_sub(long_rows * long) {
            None => (k / long, k % long, long),
            Some(j) => (long_rows + j / short, j % short, short),
        };
        let first = row * short + row.min(long_rows);
        let r = rng.next_2d();
        Vec2::new((col as f32 + r.x) / len as f32, (first as f32 + r.y * len as f32) / n as f32)
    }
}

/// How a path's random numbers are drawn across a pixel's samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SamplerKind {
    /// Only the sample positions are stratified ([`Strata`]); every other number is independent (the
    /// path tracer's only sampler before [`SamplerKind::Stratified`]).
    Independent,
    /// The path tracer's light and bounce samples, and its choice among several lights, are stratified
    /// too, each dimension over the pixel's samples in its own random order
    /// ([`SampleStream::padded_2d`], [`SampleStream::padded_1d`]). The default: less noise for the same
    /// samples. The other integrators draw the same numbers with either kind.
    #[default]
    Stratified,
    /// As [`SamplerKind::Stratified`], each dimension over the pixel's samples in its own random order,
    /// but every 2D value (the position in the pixel too) a point of Sobol's (0,2)-sequence scrambled by
    /// Owen's method ([`sobol`]; pbrt-v4's padded Sobol sampler) instead of a jittered cell: over `2^m`
    /// samples a dimension's points fill every box of area `2^-m` of every shape, not only a grid's
    /// cells, so smooth integrands converge faster. Each point is still uniform on its own: unbiased.
    Sobol,
}

impl SamplerKind {
    /// The version of the numbers this sampler gives a pixel sample, raised whenever they change: the
    /// slice identity names it, so that slices of a render made before such a change do not merge with
    /// slices made after it. `sampler_stream_versions_pin_their_numbers` fails until it is raised.
    pub fn stream_version(self) -> u32 {
        match self {
            SamplerKind::Independent => 1,
            SamplerKind::Stratified => 3,
            SamplerKind::Sobol => 1,
        }
    }
}

/// The random numbers of one pixel sample: its [`Rng`] stream, and with [`SamplerKind::Stratified`] the
/// padded dimensions (pbrt's stratified sampler, "padding" the dimensions with independent
/// permutations; Kensler 2013, "Correlated Multi-Jittered Sampling", for the permutation without a
/// table): the `d`-th value that sample `k` asks for lies in cell `π_d(k)`, of the pixel's [`Strata`]
/// grid for a 2D value and of `n` equal intervals of `[0, 1)` for one number, `π_d` a random
/// permutation of the `n` samples chosen by the pixel, the seed and `d`, independently of every other
/// dimension's. Over the pixel's samples every cell of every dimension is used once, so each value is
/// still uniform on its own and every estimate stays unbiased; only the samples' joint spread changes.
/// With [`SamplerKind::Sobol`] the value is instead point `π_d(k)` of Sobol's sequence, scrambled for the
/// pixel and `d` ([`sobol`]).
#[derive(Debug, Clone)]
pub struct SampleStream {
    /// The sample's own stream: every number that is not a padded dimension, and the jitter in a cell.
    pub rng: Rng,
    padded: Option<Padded>,
}

#[derive(Debug, Clone)]
struct Padded {
    strata: Strata,
    sample: u32,
    key: u32,
    next: u32,
    /// Scrambled Sobol points rather than jittered cells ([`SamplerKind::Sobol`]).
    sobol: bool,
}

impl Padded {
    /// The next padded dimension, jittered in its cell by `rng` (a scrambled Sobol point with
    /// [`SamplerKind::Sobol`]). Out of line: the path tracer asks at
    /// several places, and inlined there this body crowds the callers' registers.
    #[inline(never)]
    fn next_2d(&mut self, rng: &mut Rng) -> Vec2 {
        let (cell, hash) = self.next_cell();
        if self.sobol {
            return Vec2::from_array(sobol::point_2d(cell, mix(hash)));
        }
        self.strata.offset(cell, rng)
    }

    /// The next padded dimension of one number: in `1/n`-wide cell `π_d(k)` of `[0, 1)`.
    #[inline(never)]
    fn next_1d(&mut self, rng: &mut Rng) -> f32 {
        let (cell, hash) = self.next_cell();
        if self.sobol {
            return sobol::point_1d(cell, mix(hash) as u32);
        }
        let n = self.strata.n;
        let x = (cell as f32 + rng.next_f32()) / n as f32;
        // The sum rounds up to `n` for large `n`; the interval stays open.
        x.min(1.0 - f32::EPSILON / 2.0)
    }

    /// The cell of this sample in the next dimension, `π_d(k)`, and the dimension's hash, whose high half
    /// keys the permutation (and which, mixed again, seeds a Sobol point's scrambling).
    #[inline(always)]
    fn next_cell(&mut self) -> (u32, u64) {
        let hash = dimension_hash(self.key, self.next);
        self.next += 1;
        (permute(self.sample, self.strata.n, (hash >> 32) as u32), hash)
    }
}

/// The hash of padded dimension `d` of the pixel whose key is `key` (`u32::MAX`: the position in the
/// pixel). Every bit of it depends on every bit of both: the dimensions' permutations must be
/// independent draws. Keys that differed by a fixed pattern (`key ^ (d + 1) * 0x9e3779b9`, before
/// stream version 3) gave permutations of 16 samples whose cells agreed across dimensions: two
/// neighbouring dimensions fell in the same half of `[0, 1)` with probability 0.19 instead of 0.25,
/// a bias in any estimate that couples them (`sampler_padded_dimensions_are_independent`).
#[inline(always)]
fn dimension_hash(key: u32, d: u32) -> u64 {
    mix(((key as u64) << 32) | d as u64)
}

impl SampleStream {
    /// The numbers of sample `sample` of `strata.n` of pixel `(x, y)` under `seed`.
    pub fn new(kind: SamplerKind, x: u32, y: u32, sample: u32, seed: u64, strata: Strata) -> Self {
        let rng = Rng::for_sample(x, y, sample, seed);
        // One sample has nothing to stratify against (and `Strata` puts it at the cell's centre).
        let padded = (kind != SamplerKind::Independent && strata.n > 1).then(|| {
            let key = mix(mix(pixel_bits(x, y)) ^ seed.rotate_left(17)) as u32;
            Padded { strata, sample, key, next: 0, sobol: kind == SamplerKind::Sobol }
        });
        SampleStream { rng, padded }
    }

    /// Where in its pixel sample `k` of `strata` lies, in `[0, 1)^2`: [`Strata::offset`], jittered by the
    /// sample's stream, or with [`SamplerKind::Sobol`] Sobol's point `k` scrambled for the pixel.
    #[inline]
    pub fn pixel_offset(&mut self, strata: Strata, k: u32) -> Vec2 {
        match &self.padded {
            Some(p) if p.sobol => Vec2::from_array(sobol::point_2d(k, mix(dimension_hash(p.key, u32::MAX)))),
            _ => strata.offset(k, &mut self.rng),
        }
    }

    /// The sample's next padded 2D dimension (see [`SampleStream`]); with [`SamplerKind::Independent`]
    /// two numbers of the stream, as [`Rng::next_2d`].
    #[inline]
    pub fn padded_2d(&mut self) -> Vec2 {
        match &mut self.padded {
            None => self.rng.next_2d(),
            Some(p) => p.next_2d(&mut self.rng),
        }
    }

    /// The sample's next padded dimension of one number, in `[0, 1)`; with [`SamplerKind::Independent`]
    /// one number of the stream, as [`Rng::next_f32`].
    #[inline]
    pub fn padded_1d(&mut self) -> f32 {
        match &mut self.padded {
            None => self.rng.next_f32(),
            Some(p) => p.next_1d(&mut self.rng),
        }
    }
}

/// Element `i` of a random permutation of `0..n` chosen by `key`, without a table (Kensler 2013,
/// "Correlated Multi-Jittered Sampling", listing 3: a hash that is invertible on the next power of two,
/// cycle-walked down to `n`, then rotated by the key).
pub fn permute(mut i: u32, n: u32, key: u32) -> u32 {
    debug_assert!(i < n);
    // All ones below the next power of two of `n`: the domain the hash is invertible on.
    let w = u32::MAX.checked_shr(n.wrapping_sub(1).leading_zeros()).unwrap_or(0);
    loop {
        i ^= key;
        i = i.wrapping_mul(0xe170_893d);
        i ^= key >> 16;
        i ^= (i & w) >> 4;
        i ^= key >> 8;
        i = i.wrapping_mul(0x0929_eb3f);
        i ^= key >> 23;
        i ^= (i & w) >> 1;
        i = i.wrapping_mul(1 | key >> 27);
        i = i.wrapping_mul(0x6935_fa69);
        i ^= (i & w) >> 11;
        i = i.wrapping_mul(0x74dc_b303);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0x9e50_1cc3);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0xc860_a3df);
        i &= w;
        i ^= i >> 5;
        if i < n {
            break;
        }
    }
    // Kensler's rotation `(i + p) % l` with the offset `p` in `0..n` taken from the key by a multiply
    // and shift (Lemire 2019) and the sum wrapped by one subtraction: no division, and no 32-bit
    // overflow (his sum wraps for keys near 2^32 and is then not one-to-one).
    let r = i as u64 + ((key as u64 * n as u64) >> 32);
    (if r >= n as u64 { r - n as u64 } else { r }) as u32
}

#[cfg(test)]
mod tests;
