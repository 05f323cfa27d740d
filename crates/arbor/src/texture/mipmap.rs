//! Mipmaps (Williams 1983, "Pyramidal Parametrics"): each level a 2x2 box filter of the one before,
//! down to 1x1, in the image's own texel type (8-bit levels are rounded to the nearest byte). An odd
//! side halves to its floor, its last texel joining the last box (3 wide), so every texel counts.
//! Building costs one pass over a third of the image's texels; only images that a trilinear map samples
//! get a mipmap. Levels are allocated fallibly: no room for one is an error, never an abort.
//!
//! The level of detail of a footprint `w` wide in (u, v) units is `log2(w * sqrt(width * height))`, the
//! side of the footprint in texels (Akenine-Möller et al. 2019, "Texture Level of Detail Strategies for
//! Real-Time Ray Tracing", Ray Tracing Gems ch. 20), clamped to the levels held.

use super::image::{TexImage, Texels};
use crate::math::{Color, Vec2};
use crate::{Error, Result};

impl TexImage {
    /// The image with its mipmap built (once; a third more memory, in the image's own texel type), or
    /// [`Error::OutOfMemory`] when a level cannot be allocated.
    pub fn with_mipmaps(mut self) -> Result<TexImage> {
        if self.mips.is_empty() {
            self.mips = build(&self)?;
        }
        Ok(self)
    }

    /// Trilinear filtering (Williams 1983): bilinear in the two levels around the level of detail of
    /// a footprint `footprint` wide in (u, v) units, blended by the fraction between them; texel
    /// centres at half-integers. Without a mipmap, bilinear in the image itself.
    pub fn trilinear(&self, uv: Vec2, footprint: f32) -> Color {
        let lod = lod(self, footprint);
        let k = lod.floor();
        let f = lod - k;
        let fine = self.level(k as usize).centred(uv);
        if f > 0.0 {
            fine * (1.0 - f) + self.level(k as usize + 1).centred(uv) * f
        } else {
            fine
        }
    }
}

/// Levels 1 and up of `base`'s mipmap (none for a 1x1 image).
fn build(base: &TexImage) -> Result<Vec<TexImage>> {
    let mut levels: Vec<TexImage> = Vec::new();
    loop {
        let prev = levels.last().unwrap_or(base);
        let (w, h) = (prev.width, prev.height);
        if w == 1 && h == 1 {
            return Ok(levels);
        }
        let texels = match &prev.texels {
            Texels::U8(t) => Texels::U8(half(t, w, h)?),
            Texels::F32(t) => Texels::F32(half(t, w, h)?),
        };
        levels.push(TexImage::from_texels(halved(w), halved(h), texels));
    }
}

/// The level of detail of a footprint `footprint` wide in (u, v) units in `image`: in
/// `[0, image.levels() - 1]`, 0 for a footprint that is not positive (or NaN).
fn lod(image: &TexImage, footprint: f32) -> f32 {
    let texels = (image.width as f32 * image.height as f32).sqrt();
    let lod = (footprint * texels).log2();
    let max = (image.levels() - 1) as f32;
    if lod > 0.0 {
        lod.min(max)
    } else {
        0.0
    }
}

fn halved(n: u32) -> u32 {
    (n / 2).max(1)
}

/// The texels `[a, b)` along a side of `n` that output texel `i` of `halved(n)` averages.
fn span(i: u32, n: u32) -> (u32, u32) {
    let a = 2 * i;
    let b = if i + 1 == halved(n) { n } else { a + 2 };
    (a.min(n - 1), b)
}

/// A texel channel that can be averaged.
trait Channel: Copy {
    type Sum: Copy + Default;
    fn add(sum: Self::Sum, v: Self) -> Self::Sum;
    fn mean(sum: Self::Sum, n: u32) -> Self;
}

impl Channel for u8 {
    type Sum = u32;
    fn add(sum: u32, v: u8) -> u32 {
        sum + v as u32
    }
    fn mean(sum: u32, n: u32) -> u8 {
        ((sum + n / 2) / n) as u8
    }
}

impl Channel for f32 {
    type Sum = f32;
    fn add(sum: f32, v: f32) -> f32 {
        sum + v
    }
    fn mean(sum: f32, n: u32) -> f32 {
        sum / n as f32
    }
}

/// The next level of RGB texels `src` (`w` x `h`, row-major).
fn half<T: Channel>(src: &[T], w: u32, h: u32) -> Result<Vec<T>> {
    let (hw, hh) = (halved(w), halved(h));
    let n = 3 * hw as usize * hh as usize;
    let mut out = Vec::new();
    if out.try_reserve_exact(n).is_err() {
        let gib = (n * std::mem::size_of::<T>()) as f64 / (1u64 << 30) as f64;
        return Err(Error::OutOfMemory(format!("not enough memory for its mipmap's {hw}x{hh} level ({gib:.1} GiB)")));
    }
    for y in 0..hh {
        let (y0, y1) = span(y, h);
        for x in 0..hw {
            let (x0, x1) = span(x, w);
            let n = (x1 - x0) * (y1 - y0);
            for c in 0..3 {
                let mut sum = T::Sum::default();
                for yy in y0..y1 {
                    for xx in x0..x1 {
                        sum = T::add(sum, src[3 * (yy * w + xx) as usize + c]);
                    }
                }
                out.push(T::mean(sum, n));
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A grey image from one value per texel.
    fn grey(w: u32, h: u32, v: &[u8]) -> TexImage {
        TexImage::from_rgb8(w, h, v.iter().flat_map(|&g| [g; 3]).collect())
    }

    fn greys(img: &TexImage) -> Vec<f32> {
        (0..img.height as i64)
            .flat_map(|y| (0..img.width as i64).map(move |x| (x, y)))
            .map(|(x, y)| img.texel(x, y).x)
            .collect()
    }

    #[test]
    fn mipmap_level_one_of_a_4x4_image_is_its_2x2_box_means() {
        #[rustfmt::skip]
        let img = grey(4, 4, &[
            0, 4, 10, 20,
            8, 12, 30, 40,
            100, 100, 1, 2,
            100, 100, 3, 5,
        ]).with_mipmaps().unwrap();
        assert_eq!(img.levels(), 3);
        let l1 = img.level(1);
        assert_eq!((l1.width, l1.height), (2, 2));
        // (0+4+8+12)/4 = 6, (10+20+30+40)/4 = 25, 100, and (1+2+3+5)/4 = 2.75, rounded to 3.
        assert_eq!(greys(l1), [6.0, 25.0, 100.0, 3.0]);
        // Level 2 averages level 1: (6+25+100+3)/4 = 33.5, rounded half up.
        assert_eq!(greys(img.level(2)), [34.0]);
        assert!(img.is_8bit() && l1.is_8bit());
        // Beyond the coarsest level, the coarsest.
        assert_eq!(img.level(7).width, 1);
    }

    #[test]
    fn mipmap_odd_sides_fold_their_last_texel_into_the_last_box() {
        // 5x1: boxes {0, 1} and {2, 3, 4}; then 2x1 -> 1x1.
        let img = grey(5, 1, &[10, 20, 30, 60, 90]).with_mipmaps().unwrap();
        assert_eq!(img.levels(), 3);
        assert_eq!((img.level(1).width, img.level(1).height), (2, 1));
        assert_eq!(greys(img.level(1)), [15.0, 60.0]);
        assert_eq!(greys(img.level(2)), [38.0]);
        // 3x3: one box of all nine.
        let img = grey(3, 3, &[0, 9, 0, 9, 0, 9, 0, 9, 0]).with_mipmaps().unwrap();
        assert_eq!(img.levels(), 2);
        assert_eq!(greys(img.level(1)), [4.0]);
        // A 1x1 image has no levels to build.
        assert_eq!(grey(1, 1, &[7]).with_mipmaps().unwrap().levels(), 1);
    }

    #[test]
    fn mipmap_float_levels_stay_unrounded() {
        let img = TexImage::from_texels(2, 1, Texels::F32(vec![0.5, 1.0, 2.0, 1.0, 2.0, 4.0])).with_mipmaps().unwrap();
        assert!(!img.level(1).is_8bit());
        assert_eq!(img.level(1).texel(0, 0), Color::new(0.75, 1.5, 3.0));
    }

    #[test]
    fn mipmap_level_of_detail_is_the_footprint_in_texels() {
        let img = grey(8, 8, &[0; 64]).with_mipmaps().unwrap();
        // One texel per footprint: level 0; two: 1; four: 2; beyond the 1x1 level: clamped to 3.
        assert_eq!(lod(&img, 1.0 / 8.0), 0.0);
        assert_eq!(lod(&img, 2.0 / 8.0), 1.0);
        assert!((lod(&img, 2.0f32.powf(1.5) / 8.0) - 1.5).abs() < 1e-6);
        assert_eq!(lod(&img, 100.0), 3.0);
        // Smaller than a texel, zero, NaN: the image itself.
        for f in [0.01, 0.0, f32::NAN, -1.0] {
            assert_eq!(lod(&img, f), 0.0, "{f}");
        }
        // A non-square image counts sqrt(width * height) texels per unit: 32x2 is 8 per unit.
        let wide = grey(32, 2, &[0; 64]).with_mipmaps().unwrap();
        assert_eq!(lod(&wide, 4.0 / 8.0), 2.0);
        // Without a mipmap there is only level 0.
        assert_eq!(lod(&grey(8, 8, &[0; 64]), 1.0), 0.0);
    }

    #[test]
    fn mipmap_trilinear_blends_the_two_levels_around_the_level_of_detail() {
        // 2x2 of 0, 100 / 200, 40: level 1 is the 1x1 mean 85.
        let img = grey(2, 2, &[0, 100, 200, 40]).with_mipmaps().unwrap();
        let at = Vec2::new(0.25, 0.25);
        // Level 0 alone at a texel centre: that texel.
        assert_eq!(img.trilinear(at, 0.0).x, 0.0);
        // Level 0.25 (footprint 2^0.25 texels of the 2-texel image): 0.75 * 0 + 0.25 * 85.
        let f = 2.0f32.powf(0.25) / 2.0;
        assert!((img.trilinear(at, f).x - 21.25).abs() < 1e-3, "{}", img.trilinear(at, f));
        // Between texel centres at level 0 (x = 1, y = 0.5 in texels: halfway along the top row), level
        // 0.5: 0.5 * 50 + 0.5 * 85.
        let f = 2.0f32.sqrt() / 2.0;
        assert!((img.trilinear(Vec2::new(0.5, 0.25), f).x - 67.5).abs() < 1e-3);
        // A footprint past the image: its mean.
        assert_eq!(img.trilinear(at, 10.0).x, 85.0);
    }
}
