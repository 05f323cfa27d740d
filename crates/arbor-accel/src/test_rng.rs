//! The seeded generator of the library's unit tests (xorshift64*): small, deterministic, good enough to
//! scatter triangles and rays.

use crate::math::Vec3;

/// xorshift64* over a 64-bit state; the seed must not be zero.
pub(crate) struct Rng(pub u64);

impl Rng {
    /// Uniform in `[0, 1)`, 24 bits.
    pub(crate) fn f32(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40) as f32 / (1u64 << 24) as f32
    }
    /// Uniform in the unit cube.
    pub(crate) fn vec3(&mut self) -> Vec3 {
        Vec3::new(self.f32(), self.f32(), self.f32())
    }
}
