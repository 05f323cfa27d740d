//! Seeded random triangle soups for the structures' conformance suites (`accel_conformance.rs`,
//! `accel_closest_point.rs`).

use arbor::geometry::TriangleMesh;
use arbor::math::{Aabb, Vec3};

/// xorshift64*: seeded, so a failure names a reproducible case.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1)
    }
    pub fn u32(&mut self) -> u32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 32) as u32
    }
    pub fn below(&mut self, n: usize) -> usize {
        self.u32() as usize % n
    }
    /// Uniform in [0, 1).
    pub fn f32(&mut self) -> f32 {
        (self.u32() >> 8) as f32 / (1u32 << 24) as f32
    }
    pub fn vec3(&mut self) -> Vec3 {
        Vec3::new(self.f32(), self.f32(), self.f32())
    }
    pub fn in_box(&mut self, b: &Aabb) -> Vec3 {
        b.min + self.vec3() * (b.max - b.min)
    }
    pub fn pick<T: Copy>(&mut self, xs: &[T]) -> T {
        xs[self.below(xs.len())]
    }
}

/// The unwelded mesh of `tris` (triangle `i` is `tris[i]`).
pub fn mesh_of(tris: &[[Vec3; 3]]) -> TriangleMesh {
    TriangleMesh {
        positions: tris.iter().flatten().copied().collect(),
        indices: (0..tris.len() as u32).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect(),
        ..Default::default()
    }
}

/// `n` triangles of corners within `tri_size` of random centres in a cube of side `extent`.
pub fn random_soup(rng: &mut Rng, n: usize, extent: f32, tri_size: f32) -> Vec<[Vec3; 3]> {
    (0..n)
        .map(|_| {
            let c = rng.vec3() * extent;
            [0; 3].map(|_| c + (rng.vec3() - 0.5) * tri_size)
        })
        .collect()
}

/// The surface of the cube `[0, n]^3` as unit squares: closed, so every ray from inside hits it.
pub fn closed_cube(n: u32) -> Vec<[Vec3; 3]> {
    let mut tris = Vec::new();
    for axis in 0..3 {
        for k in [0, n] {
            for i in 0..n {
                for j in 0..n {
                    let [a, b, c, d] = [(0, 0), (1, 0), (1, 1), (0, 1)].map(|(di, dj)| {
                        let mut p = Vec3::ZERO;
                        p[axis] = k as f32;
                        p[(axis + 1) % 3] = (i + di) as f32;
                        p[(axis + 2) % 3] = (j + dj) as f32;
                        p
                    });
                    tris.extend([[a, b, c], [a, c, d]]);
                }
            }
        }
    }
    tris
}
