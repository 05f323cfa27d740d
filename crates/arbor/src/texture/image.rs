//! Image textures: texels kept as the file stores them (8-bit images as `u8`, EXR and HDR as `f32`),
//! sampled at (u, v) with u to the right and v down from the top-left corner, repeating outside [0, 1];
//! nearest or bilinear (pbrt-v4 §10.4.3), with edge texels repeated for the bilinear neighbours; or
//! trilinear over a mipmap ([`super::mipmap`]), which an image holds only once it is asked for one.
//!
//! The course's bilinear puts a texel's value at its top-left corner (the hw4 references depend on
//! it); trilinear puts it at the texel's centre, as pbrt-v4 does, so that every level lines up with
//! the one below it.

use std::path::Path;

use crate::image_io::{self, ImageLimits};
use crate::math::{Color, Vec2};
use crate::Result;

/// Texel storage.
#[derive(Debug)]
pub(super) enum Texels {
    /// 8-bit RGB, row-major from the top.
    U8(Vec<u8>),
    /// Float RGB, row-major from the top.
    F32(Vec<f32>),
}

/// An image loaded for texturing; shared by every map that samples it.
#[derive(Debug)]
pub struct TexImage {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    pub(super) texels: Texels,
    /// Levels 1 and up of the mipmap, each half the size of the one before down to 1x1; empty until
    /// [`TexImage::with_mipmaps`].
    pub(super) mips: Vec<TexImage>,
}

impl TexImage {
    /// An 8-bit RGB image, row-major from the top.
    ///
    /// # Panics
    /// When `bytes` is not `3 * width * height` long or the image is empty.
    pub fn from_rgb8(width: u32, height: u32, bytes: Vec<u8>) -> TexImage {
        assert!(width > 0 && height > 0 && bytes.len() == 3 * width as usize * height as usize);
        TexImage::from_texels(width, height, Texels::U8(bytes))
    }

    pub(super) fn from_texels(width: u32, height: u32, texels: Texels) -> TexImage {
        TexImage { width, height, texels, mips: Vec::new() }
    }

    /// Levels of detail held: 1 without a mipmap, else `1 + floor(log2(max(width, height)))`.
    pub fn levels(&self) -> usize {
        1 + self.mips.len()
    }

    /// Level `k` of the mipmap (0: the image itself), the coarsest held when `k` is beyond it.
    pub fn level(&self, k: usize) -> &TexImage {
        match k.checked_sub(1) {
            None => self,
            Some(i) => self.mips.get(i).or(self.mips.last()).unwrap_or(self),
        }
    }

    /// Reads PNG or JPEG as 8-bit texels, EXR and HDR as floats (which must be finite), within `limits`.
    pub fn load(path: &Path, limits: &ImageLimits) -> Result<TexImage> {
        let hdr = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        let (w, h, texels) = if matches!(hdr.as_deref(), Some("exr" | "hdr")) {
            let (w, h, texels) = image_io::read::<f32>(path, limits)?;
            image_io::check_finite(texels.chunks_exact(3).map(|c| [c[0], c[1], c[2]]), w, path)?;
            (w, h, Texels::F32(texels))
        } else {
            let (w, h, bytes) = image_io::read::<u8>(path, limits)?;
            (w, h, Texels::U8(bytes))
        };
        if w == 0 || h == 0 {
            let msg = "image has no texels".to_string();
            return Err(crate::Error::input(crate::Location::file(path), msg));
        }
        Ok(TexImage::from_texels(w, h, texels))
    }

    /// Whether texels are 8-bit.
    pub fn is_8bit(&self) -> bool {
        matches!(self.texels, Texels::U8(_))
    }

    /// The texel at column `x`, row `y` (clamped to the image), as stored (0-255 for 8-bit images).
    #[inline]
    pub fn texel(&self, x: i64, y: i64) -> Color {
        let x = x.clamp(0, self.width as i64 - 1) as usize;
        let y = y.clamp(0, self.height as i64 - 1) as usize;
        let i = 3 * (y * self.width as usize + x);
        match &self.texels {
            Texels::U8(b) => Color::new(b[i] as f32, b[i + 1] as f32, b[i + 2] as f32),
            Texels::F32(f) => Color::new(f[i], f[i + 1], f[i + 2]),
        }
    }

    /// The texel nearest to `uv` (the one the point falls in).
    #[inline]
    pub fn nearest(&self, uv: Vec2) -> Color {
        let (x, y) = self.texel_coords(uv);
        self.texel(x.floor() as i64, y.floor() as i64)
    }

    /// The four texels around `uv` weighted by distance, texel corners at integer coordinates.
    #[inline]
    pub fn bilinear(&self, uv: Vec2) -> Color {
        let (x, y) = self.texel_coords(uv);
        self.lerp(x, y)
    }

    /// The four texels around continuous texel coordinates (x, y), texel (i, j) at (i, j).
    #[inline]
    fn lerp(&self, x: f32, y: f32) -> Color {
        let (px, py) = (x.floor(), y.floor());
        let (dx, dy) = (x - px, y - py);
        let (px, py) = (px as i64, py as i64);
        self.texel(px, py) * ((1.0 - dx) * (1.0 - dy))
            + self.texel(px + 1, py) * (dx * (1.0 - dy))
            + self.texel(px, py + 1) * ((1.0 - dx) * dy)
            + self.texel(px + 1, py + 1) * (dx * dy)
    }

    /// Bilinear with texel centres at half-integer coordinates.
    #[inline]
    pub(super) fn centred(&self, uv: Vec2) -> Color {
        let (x, y) = self.texel_coords(uv);
        self.lerp(x - 0.5, y - 0.5)
    }

    /// Continuous texel coordinates of `uv`, repeated into the image.
    #[inline]
    fn texel_coords(&self, uv: Vec2) -> (f32, f32) {
        let (u, v) = (uv.x - uv.x.floor(), uv.y - uv.y.floor());
        (u * self.width as f32, v * self.height as f32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 2x2: red, green / blue, white.
    fn img() -> TexImage {
        TexImage::from_rgb8(2, 2, vec![255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255])
    }

    #[test]
    fn image_nearest_picks_the_texel_the_point_falls_in() {
        let i = img();
        assert_eq!(i.nearest(Vec2::new(0.25, 0.25)), Color::new(255.0, 0.0, 0.0));
        assert_eq!(i.nearest(Vec2::new(0.75, 0.25)), Color::new(0.0, 255.0, 0.0));
        assert_eq!(i.nearest(Vec2::new(0.25, 0.75)), Color::new(0.0, 0.0, 255.0));
        // Repeats outside [0, 1].
        assert_eq!(i.nearest(Vec2::new(1.75, -0.25)), Color::splat(255.0));
    }

    #[test]
    fn image_bilinear_weights_by_distance_and_repeats_edges() {
        let i = img();
        // Halfway between the four texel corners (1, 1), (2, 1), (1, 2), (2, 2): only (1, 1) is inside;
        // the others repeat the edge texels.
        assert_eq!(i.bilinear(Vec2::new(0.5, 0.5)), Color::splat(255.0));
        // x = 0.5, y = 0: half red, half green.
        assert!(i.bilinear(Vec2::new(0.25, 0.0)).abs_diff_eq(Color::new(127.5, 127.5, 0.0), 1e-4));
        // x = 0.5, y = 0.5: the mean of all four.
        assert!(i.bilinear(Vec2::new(0.25, 0.25)).abs_diff_eq(Color::new(127.5, 127.5, 127.5), 1e-4));
    }

    /// 3x3 greys, texel (x, y) at index 3y + x.
    fn grid() -> TexImage {
        TexImage::from_rgb8(3, 3, [0u8, 10, 20, 30, 40, 80, 60, 120, 200].iter().flat_map(|&g| [g; 3]).collect())
    }

    #[test]
    fn image_bilinear_matches_a_value_worked_by_hand() {
        // Texel coordinates (1.25, 1.5): weights 0.75 * 0.5 on (1, 1) = 40 and on (1, 2) = 120, 0.25 * 0.5
        // on (2, 1) = 80 and on (2, 2) = 200: 15 + 45 + 10 + 25 = 95.
        let v = grid().bilinear(Vec2::new(1.25 / 3.0, 0.5));
        assert!((v.x - 95.0).abs() < 1e-3, "{v}");
        // (2.5, 0.5): the right neighbours are past the edge and repeat column 2: the mean of (2, 0) = 20
        // and (2, 1) = 80.
        let v = grid().bilinear(Vec2::new(2.5 / 3.0, 0.5 / 3.0));
        assert!((v.x - 50.0).abs() < 1e-3, "{v}");
    }

    #[test]
    fn image_nearest_takes_the_texel_on_the_far_side_of_an_edge() {
        let g = grid();
        let at = |x: f32, y: f32| g.nearest(Vec2::new(x / 3.0, y / 3.0)).x;
        // Texel centres, then the edge x = 1 belonging to column 1 and just before it to column 0.
        assert_eq!([at(0.5, 0.5), at(1.5, 1.5), at(2.5, 2.5)], [0.0, 40.0, 200.0]);
        assert_eq!([at(1.0, 0.5), at(0.999, 0.5), at(1.0, 2.0)], [10.0, 0.0, 120.0]);
    }
}
