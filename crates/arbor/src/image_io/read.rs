//! Reading images into films (display units), float or 8-bit RGB, within a pixel budget.
//!
//! The format is recognised by the file's first bytes, then by its extension. Files are read whole by
//! [`crate::input::load_bytes`] (regular files only, never more than their length when opened) before
//! they are decoded, in three steps, each bounded:
//!
//! 1. the header: the decoder (the image crate's; for OpenEXR the exr crate's, [`super::openexr`]) reads the
//!    dimensions, which are checked against the [`ImageLimits`] before anything is sized by them;
//! 2. the samples: decoded into a buffer reserved fallibly, in the file's own layout (8-bit, 16-bit or
//!    float; grey, grey and alpha, RGB or RGBA);
//! 3. the conversion to what the caller asked for ([`Texel`]): into a buffer reserved fallibly, in runs
//!    of 65,536 pixels, each converted by the image crate's own `into_rgb8` or `into_rgb32f`, so that the
//!    texels are exactly those of converting the whole image at once, with no transient copy of it.
//!
//! Integer samples are divided by their maximum (255 or 65535), float samples (EXR, HDR) are kept as
//! they are (8-bit output clamps them to [0, 1] first, and takes NaN as 1, as the image crate does);
//! grey is expanded to RGB and alpha is dropped, never composited, because references are compared as
//! stored. Peak memory: the decoded samples plus the converted texels.
//!
//! A file that cannot be decoded, one cut short included, is bad input ([`Error::Input`]); only a file
//! that cannot be read at all is an I/O error, and so is a buffer that cannot be allocated.

use std::io::Cursor;
use std::path::Path;

use image::{ColorType, DynamicImage, ImageBuffer, ImageDecoder, ImageFormat, ImageReader};

use super::limits::{try_vec, ImageLimits};
use crate::error::{Error, Location, Result};
use crate::film::Film;
use crate::math::Color;

/// Pixels converted at a time: the transient buffers of a conversion never hold more.
const RUN: usize = 1 << 16;

/// What an image is converted to: `u8` (8-bit RGB, three per pixel), `f32` (float RGB, three per pixel)
/// or [`Color`] (one per pixel).
pub trait Texel: sealed::Convert {}
impl Texel for u8 {}
impl Texel for f32 {}
impl Texel for Color {}

mod sealed {
    /// The conversion of a run of pixels, by the image crate.
    pub trait Convert: Sized {
        /// Items per pixel.
        const PER_PIXEL: u64;
        /// Appends `run`'s pixels to `out`, which has room for them.
        fn append(out: &mut Vec<Self>, run: image::DynamicImage);
    }
}

impl sealed::Convert for u8 {
    const PER_PIXEL: u64 = 3;
    fn append(out: &mut Vec<u8>, run: DynamicImage) {
        out.extend_from_slice(run.into_rgb8().as_raw());
    }
}

impl sealed::Convert for f32 {
    const PER_PIXEL: u64 = 3;
    fn append(out: &mut Vec<f32>, run: DynamicImage) {
        out.extend_from_slice(run.into_rgb32f().as_raw());
    }
}

impl sealed::Convert for Color {
    const PER_PIXEL: u64 = 1;
    fn append(out: &mut Vec<Color>, run: DynamicImage) {
        out.extend(run.into_rgb32f().as_raw().chunks_exact(3).map(|c| Color::new(c[0], c[1], c[2])));
    }
}

/// Reads PNG, JPEG, PNM (8 or 16-bit), OpenEXR or Radiance HDR into a film, within the default budget
/// ([`ImageLimits::DEFAULT`]). Errors name the file.
pub fn read_image(path: &Path) -> Result<Film> {
    read_image_within(path, &ImageLimits::DEFAULT)
}

/// [`read_image`] within `limits`.
pub fn read_image_within(path: &Path, limits: &ImageLimits) -> Result<Film> {
    let (width, height, pixels) = read(path, limits)?;
    Ok(Film { width, height, pixels })
}

/// Reads an image as 8-bit RGB, row-major from the top: `(width, height, bytes)`, within the default
/// budget. 16-bit samples are rounded to 8 bits and float samples clamped to [0, 1] first.
pub fn read_rgb8(path: &Path) -> Result<(u32, u32, Vec<u8>)> {
    read(path, &ImageLimits::DEFAULT)
}

/// Reads an image as `T` texels, row-major from the top: `(width, height, texels)`.
pub fn read<T: Texel>(path: &Path, limits: &ImageLimits) -> Result<(u32, u32, Vec<T>)> {
    decode(&crate::input::load_bytes(path)?, path, limits)
}

/// Decodes the file `bytes` (named `path` in errors, whose extension is the format when the bytes do not
/// tell) as `T` texels, row-major from the top: `(width, height, texels)`.
pub fn decode<T: Texel>(bytes: &[u8], path: &Path, limits: &ImageLimits) -> Result<(u32, u32, Vec<T>)> {
    let (width, height, color, samples) = decode_samples(bytes, path, limits)?;
    let n = (width as u64 * height as u64).saturating_mul(T::PER_PIXEL);
    let mut out = try_vec(n, width, height, "convert it", path)?;
    for run in samples.chunks(RUN * color.bytes_per_pixel() as usize) {
        T::append(&mut out, run_image(color, run).expect("a run of whole pixels of a supported layout"));
    }
    Ok((width, height, out))
}

/// The decoded samples of an image in the file's layout, native-endian: `(width, height, layout, bytes)`.
fn decode_samples(bytes: &[u8], path: &Path, limits: &ImageLimits) -> Result<(u32, u32, ColorType, Vec<u8>)> {
    let mut reader = ImageReader::new(Cursor::new(bytes));
    if let Ok(format) = ImageFormat::from_path(path) {
        reader.set_format(format);
    }
    let mut reader = reader.with_guessed_format().map_err(|e| Error::io(path, e))?;
    match reader.format() {
        Some(ImageFormat::OpenExr) => return super::openexr::decode_rgb(bytes, path, limits),
        Some(ImageFormat::Jpeg) if !super::jpeg::is_whole(bytes) => {
            let msg = "cannot decode image: the JPEG data ends before its end-of-image marker (the file is truncated)";
            return Err(Error::input(Location::file(path), msg));
        }
        Some(ImageFormat::Png) => {
            if let Some(len) = super::png::broken_palette(bytes) {
                let msg = format!("cannot decode image: its palette (PLTE) holds {len} bytes, not whole RGB entries");
                return Err(Error::input(Location::file(path), msg));
            }
        }
        _ => {}
    }
    // The image crate's own allocation limit (512 MiB) bounds what its decoders allocate besides the
    // pixels (text chunks, say); lifted with the budget.
    if *limits == ImageLimits::NONE {
        reader.no_limits();
    }
    let decoder = reader.into_decoder().map_err(|e| undecodable(path, e))?;
    let (width, height) = decoder.dimensions();
    limits.check(width, height, path)?;
    let color = decoder.color_type();
    if run_image(color, &[]).is_none() {
        return Err(Error::input(Location::file(path), format!("cannot decode image: unsupported layout {color:?}")));
    }
    let total = decoder.total_bytes();
    let mut samples = try_vec(total, width, height, "decode it", path)?;
    samples.resize(total as usize, 0);
    decoder.read_image(&mut samples).map_err(|e| undecodable(path, e))?;
    Ok((width, height, color, samples))
}

/// Refuses an image `width` pixels wide (read from `path`) holding a NaN or an infinity, naming the
/// first pixel that does: what needs radiance or float texels calls this, as float files can hold them.
pub fn check_finite(pixels: impl IntoIterator<Item = [f32; 3]>, width: u32, path: &Path) -> Result<()> {
    let Some((i, [r, g, b])) = pixels.into_iter().enumerate().find(|(_, p)| !p.iter().all(|v| v.is_finite())) else {
        return Ok(());
    };
    let (x, y) = (i as u64 % width.max(1) as u64, i as u64 / width.max(1) as u64);
    Err(Error::input(Location::file(path), format!("pixel ({x}, {y}) is not finite: ({r}, {g}, {b})")))
}

/// The error of a decoder.
pub(super) fn undecodable(path: &Path, e: image::ImageError) -> Error {
    let why = match e {
        // The bytes are already in memory, so a decoder's I/O error is the data's fault, never the
        // disk's: bad input (exit 3), like any other undecodable file.
        image::ImageError::IoError(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => {
            "unexpected end of file (the file is truncated)".to_string()
        }
        other => other.to_string(),
    };
    Error::input(Location::file(path), format!("cannot decode image: {why}"))
}

/// The whole pixels of `bytes` (samples of layout `color`, native-endian) as a one-row image; `None` for
/// a layout no decoder of Arbor's formats gives.
fn run_image(color: ColorType, bytes: &[u8]) -> Option<DynamicImage> {
    let n = (bytes.len() / color.bytes_per_pixel().max(1) as usize) as u32;
    let u16s = || bytes.chunks_exact(2).map(|b| u16::from_ne_bytes([b[0], b[1]])).collect::<Vec<_>>();
    let f32s = || bytes.chunks_exact(4).map(|b| f32::from_ne_bytes([b[0], b[1], b[2], b[3]])).collect::<Vec<_>>();
    Some(match color {
        ColorType::L8 => DynamicImage::ImageLuma8(ImageBuffer::from_raw(n, 1, bytes.to_vec())?),
        ColorType::La8 => DynamicImage::ImageLumaA8(ImageBuffer::from_raw(n, 1, bytes.to_vec())?),
        ColorType::Rgb8 => DynamicImage::ImageRgb8(ImageBuffer::from_raw(n, 1, bytes.to_vec())?),
        ColorType::Rgba8 => DynamicImage::ImageRgba8(ImageBuffer::from_raw(n, 1, bytes.to_vec())?),
        ColorType::L16 => DynamicImage::ImageLuma16(ImageBuffer::from_raw(n, 1, u16s())?),
        ColorType::La16 => DynamicImage::ImageLumaA16(ImageBuffer::from_raw(n, 1, u16s())?),
        ColorType::Rgb16 => DynamicImage::ImageRgb16(ImageBuffer::from_raw(n, 1, u16s())?),
        ColorType::Rgba16 => DynamicImage::ImageRgba16(ImageBuffer::from_raw(n, 1, u16s())?),
        ColorType::Rgb32F => DynamicImage::ImageRgb32F(ImageBuffer::from_raw(n, 1, f32s())?),
        ColorType::Rgba32F => DynamicImage::ImageRgba32F(ImageBuffer::from_raw(n, 1, f32s())?),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every layout the decoders give, with samples covering their range (and, for floats, values out of
    /// [0, 1], infinities and NaN), read run by run and whole by the image crate: the same texels.
    #[test]
    fn read_runs_convert_exactly_as_the_whole_image_does() {
        let (w, h) = (300u32, 700u32); // 210,000 pixels: three full runs and a partial one
        let n = (w * h) as usize;
        let floats = [0.0f32, 0.25, 1.0, 1.5, -0.5, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, 1e-40, 0.5019608];
        let u8s = |c: usize| (0..n * c).map(|i| (i * 7 % 256) as u8).collect::<Vec<_>>();
        let u16s = |c: usize| (0..n * c).map(|i| (i * 257 % 65536) as u16).collect::<Vec<_>>();
        let f32s = |c: usize| (0..n * c).map(|i| floats[i % floats.len()] * (1 + i % 3) as f32).collect::<Vec<_>>();
        let images = [
            DynamicImage::ImageLuma8(ImageBuffer::from_raw(w, h, u8s(1)).unwrap()),
            DynamicImage::ImageLumaA8(ImageBuffer::from_raw(w, h, u8s(2)).unwrap()),
            DynamicImage::ImageRgb8(ImageBuffer::from_raw(w, h, u8s(3)).unwrap()),
            DynamicImage::ImageRgba8(ImageBuffer::from_raw(w, h, u8s(4)).unwrap()),
            DynamicImage::ImageLuma16(ImageBuffer::from_raw(w, h, u16s(1)).unwrap()),
            DynamicImage::ImageLumaA16(ImageBuffer::from_raw(w, h, u16s(2)).unwrap()),
            DynamicImage::ImageRgb16(ImageBuffer::from_raw(w, h, u16s(3)).unwrap()),
            DynamicImage::ImageRgba16(ImageBuffer::from_raw(w, h, u16s(4)).unwrap()),
            DynamicImage::ImageRgb32F(ImageBuffer::from_raw(w, h, f32s(3)).unwrap()),
            DynamicImage::ImageRgba32F(ImageBuffer::from_raw(w, h, f32s(4)).unwrap()),
        ];
        for image in images {
            let color = image.color();
            let bytes = image.as_bytes().to_vec();
            let convert = |out: &mut Vec<f32>, out8: &mut Vec<u8>| {
                for run in bytes.chunks(RUN * color.bytes_per_pixel() as usize) {
                    <f32 as sealed::Convert>::append(out, run_image(color, run).unwrap());
                    <u8 as sealed::Convert>::append(out8, run_image(color, run).unwrap());
                }
            };
            let (mut floats, mut bytes8) = (Vec::new(), Vec::new());
            convert(&mut floats, &mut bytes8);
            let whole = image.clone().into_rgb32f().into_raw();
            assert!(floats.iter().zip(&whole).all(|(a, b)| a.to_bits() == b.to_bits()), "{color:?}");
            assert_eq!(floats.len(), whole.len());
            assert_eq!(bytes8, image.into_rgb8().into_raw(), "{color:?}");
        }
    }

    #[test]
    fn check_finite_names_the_first_pixel_that_is_not() {
        let path = Path::new("sky.exr");
        check_finite([[0.0, 1e30, -2.0]; 4], 2, path).unwrap();
        let pixels = [[0.0; 3], [0.0; 3], [0.0; 3], [1.0, f32::NAN, 0.5], [f32::INFINITY; 3]];
        let e = check_finite(pixels, 2, path).unwrap_err().to_string();
        assert_eq!(e, "sky.exr: pixel (1, 1) is not finite: (1, NaN, 0.5)");
        let e = check_finite([[f32::NEG_INFINITY, 0.0, 0.0]], 1, path).unwrap_err().to_string();
        assert_eq!(e, "sky.exr: pixel (0, 0) is not finite: (-inf, 0, 0)");
    }

    #[test]
    fn decode_refuses_an_image_above_the_budget_before_decoding_it() {
        let mut png = Vec::new();
        image::RgbImage::new(3, 2).write_to(&mut Cursor::new(&mut png), ImageFormat::Png).unwrap();
        let limits = ImageLimits { max_pixels: 5 };
        let e = decode::<u8>(&png, Path::new("a.png"), &limits).unwrap_err().to_string();
        assert_eq!(e, "a.png: image 3x2 has 6 pixels, more than the limit of 5; --no-limits lifts the limits");
        assert_eq!(decode::<u8>(&png, Path::new("a.png"), &ImageLimits { max_pixels: 6 }).unwrap().2, vec![0; 18]);
    }
}
