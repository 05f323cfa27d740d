//! The film: a width x height grid of linear RGB in display units (1.0 = white), row 0 at the top.

use crate::error::{Error, Result};
use crate::math::Color;

/// A rendered image before it is written.
#[derive(Debug, Clone, PartialEq)]
pub struct Film {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major pixels, top row first.
    pub pixels: Vec<Color>,
}

impl Film {
    /// A black film.
    pub fn new(width: u32, height: u32) -> Self {
        Film { width, height, pixels: vec![Color::ZERO; width as usize * height as usize] }
    }
    /// A black film, or [`Error::OutOfMemory`] when its pixels cannot be allocated: a film large
    /// enough to fail is asked for before its render, not after.
    pub fn try_new(width: u32, height: u32) -> Result<Self> {
        Ok(Film { width, height, pixels: try_filled(Color::ZERO, width, height)? })
    }
    /// The pixel at column `x`, row `y`.
    #[inline]
    pub fn get(&self, x: u32, y: u32) -> Color {
        self.pixels[y as usize * self.width as usize + x as usize]
    }
    /// 8-bit RGB: each channel clamped to [0, 1], scaled to 255 and rounded to nearest, as the course
    /// references are made.
    pub fn to_rgb8(&self) -> Vec<u8> {
        self.pixels.iter().flat_map(|c| c.to_array()).map(quantize).collect()
    }
}

/// One `value` per pixel of a `width` x `height` image, or [`Error::OutOfMemory`] when they cannot be
/// allocated.
pub fn try_filled<T: Clone>(value: T, width: u32, height: u32) -> Result<Vec<T>> {
    let n = width as usize * height as usize;
    let mut v = Vec::new();
    if v.try_reserve_exact(n).is_err() {
        return Err(out_of_memory(width, height, n as u64 * std::mem::size_of::<T>() as u64));
    }
    v.resize(n, value);
    Ok(v)
}

/// The error for buffers of `bytes` for a `width` x `height` image that could not be allocated.
pub fn out_of_memory(width: u32, height: u32, bytes: u64) -> Error {
    let gib = bytes as f64 / (1u64 << 30) as f64;
    Error::OutOfMemory(format!("not enough memory for a {width}x{height} image ({gib:.1} GiB)"))
}

/// One channel to 8 bits: clamp, scale, round half up. NaN becomes 0.
#[inline]
pub fn quantize(v: f32) -> u8 {
    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    (v * 255.0 + 0.5) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn film_quantize_clamps_and_rounds() {
        assert_eq!(quantize(-1.0), 0);
        assert_eq!(quantize(f32::NAN), 0);
        assert_eq!(quantize(2.0), 255);
        assert_eq!(quantize(100.4 / 255.0), 100);
        assert_eq!(quantize(100.6 / 255.0), 101);
    }
}
