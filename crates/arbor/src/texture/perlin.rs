//! Perlin noise as the CENG 795 course's renderer computes it, in the lecture's form: sixteen
//! gradients (the twelve cube edge directions, four of them repeated, as in Perlin's "Improving
//! Noise", SIGGRAPH 2002) picked at lattice point (i, j, k) by `G[φ(i + φ(j + φ(k)))]`, with
//! `φ(x) = P[|x| mod 16]` and `P` the permutation of 0..16 that C++'s `std::random_shuffle` makes
//! with glibc's `rand()` unseeded; corners weighted by `1 - (6|t|⁵ - 15|t|⁴ + 10|t|³)` per axis
//! (Perlin's quintic fade). Zero at lattice points, in [-1, 1]. The texture turns it into [0, 1] by
//! its absolute value or linearly.

use crate::math::Vec3;

/// The gradients `G`, indexed by `φ`.
const GRADIENTS: [[f32; 3]; 16] = [
    [1.0, 1.0, 0.0],
    [-1.0, 1.0, 0.0],
    [1.0, -1.0, 0.0],
    [-1.0, -1.0, 0.0],
    [1.0, 0.0, 1.0],
    [-1.0, 0.0, 1.0],
    [1.0, 0.0, -1.0],
    [-1.0, 0.0, -1.0],
    [0.0, 1.0, 1.0],
    [0.0, -1.0, 1.0],
    [0.0, 1.0, -1.0],
    [0.0, -1.0, -1.0],
    [1.0, 1.0, 0.0],
    [-1.0, 1.0, 0.0],
    [0.0, -1.0, 1.0],
    [0.0, -1.0, -1.0],
];

/// `P`: 0..16 shuffled as the course's renderer shuffles it, so the noise is its pattern.
const PERM: [u8; 16] = random_shuffle_16();

/// glibc's `rand()` before any `srand` (seed 1): the additive feedback generator
/// `r[n] = r[n-3] + r[n-31]` (mod 2³²) over a state seeded by `16807 r mod (2³¹ - 1)`, its first 310
/// outputs discarded, each output `r[n] >> 1`. `r` holds the last 34 words, `r[n % 34]`.
struct GlibcRand {
    r: [u32; 34],
    n: usize,
}

impl GlibcRand {
    const fn new() -> Self {
        let mut r = [0u32; 34];
        r[0] = 1;
        let mut i = 1;
        while i < 31 {
            r[i] = ((16807 * r[i - 1] as u64) % 2_147_483_647) as u32;
            i += 1;
        }
        while i < 34 {
            r[i] = r[i - 31];
            i += 1;
        }
        let mut g = GlibcRand { r, n: 34 };
        while g.n < 344 {
            g.next();
        }
        g
    }

    const fn next(&mut self) -> u32 {
        let v = self.r[(self.n - 31) % 34].wrapping_add(self.r[(self.n - 3) % 34]);
        self.r[self.n % 34] = v;
        self.n += 1;
        v >> 1
    }
}

/// libstdc++'s `std::random_shuffle(first, last)` of 0..16: for each i from 1, swap element i with
/// element `rand() % (i + 1)`.
const fn random_shuffle_16() -> [u8; 16] {
    let mut p = [0u8; 16];
    let mut i = 0;
    while i < 16 {
        p[i] = i as u8;
        i += 1;
    }
    let mut rand = GlibcRand::new();
    let mut i = 1;
    while i < 16 {
        let j = (rand.next() % (i as u32 + 1)) as usize;
        let t = p[i];
        p[i] = p[j];
        p[j] = t;
        i += 1;
    }
    p
}

/// `φ(x) = P[|x| mod 16]`.
#[inline]
fn phi(x: i32) -> i32 {
    PERM[(x.unsigned_abs() % 16) as usize] as i32
}

/// The weight of a corner at offset `t` along one axis, `|t| < 1`: `1 - fade(|t|)`.
#[inline]
fn weight(t: f32) -> f32 {
    let a = t.abs();
    1.0 - a * a * a * (a * (a * 6.0 - 15.0) + 10.0)
}

/// Noise at `p`, in [-1, 1].
pub fn noise(p: Vec3) -> f32 {
    let f = p.floor();
    let (xi, yi, zi) = (f.x as i32, f.y as i32, f.z as i32);
    let mut sum = 0.0;
    for (dx, dy, dz) in [(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0), (0, 0, 1), (1, 0, 1), (0, 1, 1), (1, 1, 1)] {
        let (i, j, k) = (xi + dx, yi + dy, zi + dz);
        let d = p - Vec3::new(i as f32, j as f32, k as f32);
        let g = GRADIENTS[phi(i + phi(j + phi(k))) as usize];
        sum += weight(d.x) * weight(d.y) * weight(d.z) * (g[0] * d.x + g[1] * d.y + g[2] * d.z);
    }
    sum
}

/// The gradient of `noise` at `p`, by central differences.
pub fn gradient(p: Vec3) -> Vec3 {
    const H: f32 = 1e-3;
    let d = |e: Vec3| (noise(p + e) - noise(p - e)) / (2.0 * H);
    Vec3::new(d(Vec3::X * H), d(Vec3::Y * H), d(Vec3::Z * H))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glibc_rand_starts_as_glibc_does() {
        // The first outputs of glibc's rand() without srand, as any C program on glibc prints them.
        let mut r = GlibcRand::new();
        for want in [1_804_289_383, 846_930_886, 1_681_692_777, 1_714_636_915, 1_957_747_793] {
            assert_eq!(r.next(), want);
        }
    }

    #[test]
    fn perlin_table_is_the_shuffle_of_0_to_15() {
        // The shuffle worked by hand from those outputs: i = 1 swaps with 1804289383 % 2 = 1 (stays),
        // i = 2 with 846930886 % 3 = 1, i = 3 with 1681692777 % 4 = 1, ...; the whole table is
        // what `std::random_shuffle` over 0..16 leaves after an unseeded run with g++ and glibc.
        assert_eq!(PERM, [4, 10, 11, 15, 14, 5, 13, 1, 6, 9, 3, 7, 8, 2, 0, 12]);
    }

    #[test]
    fn perlin_is_zero_at_lattice_points() {
        for p in [Vec3::ZERO, Vec3::new(3.0, -2.0, 7.0), Vec3::new(-1.0, 0.0, 255.0)] {
            assert_eq!(noise(p), 0.0);
        }
    }

    #[test]
    fn perlin_matches_values_worked_by_hand() {
        // On the x axis (y = z = 0) only the corners (i, 0, 0) and (i + 1, 0, 0) have weight, and only
        // a gradient's x component counts. φ(0) = P[0] = 4, φ(0 + 4) = P[4] = 14:
        // corner (0,0,0) takes G[φ(0 + 14)] = G[P[14]] = G[0] = (1, 1, 0);
        // corner (1,0,0) takes G[φ(1 + 14)] = G[P[15]] = G[12] = (1, 1, 0).
        // At x = 0.25: weights 1 - fade(0.25) and fade(0.25) = 0.103515625; offsets 0.25 and -0.75.
        let t = 0.103_515_625;
        let want = (1.0 - t) * 0.25 + t * -0.75;
        assert!((noise(Vec3::new(0.25, 0.0, 0.0)) - want).abs() < 1e-6);
        // Below y = -4 the middle argument j + φ(0) = j + 4 turns negative, and φ reads its absolute
        // value: at (0, -5.5, 0) the corners (0,-6,0) and (0,-5,0) weigh 1/2 each. Corner -6:
        // φ(|-2|) = P[2] = 11, G[φ(0 + 11)] = G[P[11]] = G[7] = (-1, 0, -1), no y component. Corner -5:
        // φ(|-1|) = P[1] = 10, G[φ(10)] = G[P[10]] = G[3] = (-1, -1, 0), y offset -0.5: 1/2 · 1/2.
        // (Reading -1 as 15, a floored modulo, would give G[8] and -1/4.)
        assert!((noise(Vec3::new(0.0, -5.5, 0.0)) - 0.25).abs() < 1e-6);
        // Along z (x = y = 0) only the gradients' z components count: corner (0,0,1) takes
        // G[φ(0 + φ(0 + φ(1)))] = G[φ(φ(10))] = G[φ(3)] = G[15] = (0, -1, -1), so at z = 0.5
        // corner (0,0,0) (z component 0) adds nothing and corner (0,0,1) adds 0.5 · (-1) · (-0.5).
        assert!((noise(Vec3::new(0.0, 0.0, 0.5)) - 0.25).abs() < 1e-6);
    }

    #[test]
    fn perlin_gradient_matches_the_noise_slope() {
        let p = Vec3::new(1.3, 2.7, 0.45);
        let g = gradient(p);
        let h = 1e-2;
        let fd = (noise(p + Vec3::X * h) - noise(p)) / h;
        assert!((g.x - fd).abs() < 0.05, "{} vs {fd}", g.x);
    }

    #[test]
    fn perlin_stays_in_range() {
        for i in 0..1000 {
            let p = Vec3::new(i as f32 * 0.377, i as f32 * 0.131 - 20.0, i as f32 * 0.071);
            assert!(noise(p).abs() <= 1.0);
        }
    }
}
