//! The pixel budget of an image Arbor reads, checked from the file's header before any pixel is decoded,
//! and the fallible allocation of everything sized by it.
//!
//! A PNG of 1-bit grey compresses 530 megapixels into 50 KB (deflate reaches about 1000:1 and 1-bit grey
//! packs 8 pixels into a byte); decoding it fills 530 MB of 8-bit grey, and converting it to Arbor's
//! float texels 6.4 GB. So the dimensions in the header are checked against [`ImageLimits`] before the
//! decoder allocates anything for pixels, and every buffer sized by them afterwards (the decoded samples,
//! the converted texels, mipmaps, sampling tables) is reserved with `try_reserve_exact`: an image too
//! large for the budget is bad input naming the file, one within it (or with the budget lifted) that
//! still does not fit in memory is an out-of-memory error naming it, never an abort.
//!
//! The default, [`ImageLimits::DEFAULT`], is 2^26 pixels (8192 x 8192, or a 16384 x 4096
//! latitude-longitude map): 11 times the largest image of the course scenes (2000 x 3008, a 6-megapixel
//! JPEG texture), and at most about 1.6 GB for the largest use (a float environment map: its decoded
//! samples and the map, 24 bytes a pixel, then the map and its sampling table, 20). `arbor --no-limits`
//! lifts it ([`ImageLimits::NONE`]); the scene's limits hold the value ([`crate::scene::SceneLimits`]).

use std::path::Path;

use crate::error::{Error, Location, Result, LIFT_LIMITS};

/// How large an image may be read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ImageLimits {
    /// Largest number of pixels (width x height; for an EXR, of its display and of its data window).
    pub max_pixels: u64,
}

impl ImageLimits {
    /// The budget of an image a scene reads (a texture, an environment map, a cube face): 2^26 pixels.
    pub const DEFAULT: ImageLimits = ImageLimits { max_pixels: 1 << 26 };
    /// No budget: every allocation is still fallible.
    pub const NONE: ImageLimits = ImageLimits { max_pixels: u64::MAX };

    /// Refuses a `width` x `height` image (of the file `path`) above the budget.
    pub fn check(&self, width: u32, height: u32, path: &Path) -> Result<()> {
        self.check_area("image", width as u64, height as u64, path)
    }

    /// Refuses a `width` x `height` area (`what`: "image", "the data window") above the budget.
    pub(crate) fn check_area(&self, what: &str, width: u64, height: u64, path: &Path) -> Result<()> {
        let pixels = width.saturating_mul(height);
        if pixels > self.max_pixels {
            let msg = format!(
                "{what} {width}x{height} has {pixels} pixels, more than the limit of {}; {LIFT_LIMITS}",
                self.max_pixels
            );
            return Err(Error::input(Location::file(path), msg));
        }
        Ok(())
    }
}

impl Default for ImageLimits {
    fn default() -> Self {
        ImageLimits::DEFAULT
    }
}

/// An empty vector with room for `n` items of what a `width` x `height` image of `path` holds (`what`:
/// "decode it", "convert it"), or an out-of-memory I/O error naming the file (the CLI's exit 4; a scene's
/// texture or map is located at its element instead, like a mesh file).
pub(crate) fn try_vec<T>(n: u64, width: u32, height: u32, what: &str, path: &Path) -> Result<Vec<T>> {
    crate::input::vec_for(n, path, |gib| format!("not enough memory to {what}: {width}x{height} pixels ({gib:.1} GiB)"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_refuse_only_above_the_budget_and_say_how_to_lift_it() {
        let path = Path::new("a.png");
        ImageLimits::DEFAULT.check(8192, 8192, path).unwrap();
        let e = ImageLimits::DEFAULT.check(8192, 8193, path).unwrap_err().to_string();
        assert_eq!(
            e,
            "a.png: image 8192x8193 has 67117056 pixels, more than the limit of 67108864; --no-limits lifts the limits"
        );
        ImageLimits::NONE.check(u32::MAX, u32::MAX, path).unwrap();
        let e = ImageLimits { max_pixels: 10 }.check_area("the data window", 4, 3, path).unwrap_err();
        assert!(e.to_string().starts_with("a.png: the data window 4x3 has 12 pixels, more than the limit of 10;"));
    }

    #[test]
    fn try_vec_fails_instead_of_aborting() {
        let e = try_vec::<f32>(u64::MAX / 2, 1, 1, "decode it", Path::new("big.exr")).unwrap_err();
        assert!(e.is_io(), "{e}");
        assert!(e.to_string().starts_with("big.exr: not enough memory to decode it: 1x1 pixels ("), "{e}");
        assert_eq!(try_vec::<u8>(12, 2, 2, "decode it", Path::new("a.png")).unwrap().capacity(), 12);
    }
}
