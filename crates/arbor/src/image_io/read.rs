//! Reading images into films (display units) or into exact 8-bit RGB.
//!
//! The format is recognised by the file's first bytes, then by its extension. Files are read whole by
//! [`crate::input::load_bytes`] (regular files only, never more than their length when opened) before
//! they are decoded. Integer samples are divided
//! by their maximum (255 or 65535), float samples (EXR, HDR) are kept as they are; grey is expanded to RGB
//! and alpha is dropped, never composited, because references are compared as stored.
//!
//! A file that cannot be decoded, one cut short included, is bad input ([`Error::Input`]); only a file
//! that cannot be read at all is an I/O error.

use std::path::Path;

use std::io::Cursor;

use image::{DynamicImage, ImageFormat, ImageReader};

use crate::error::{Error, Location, Result};
use crate::film::Film;
use crate::math::Color;

/// Reads PNG, JPEG, PNM (8 or 16-bit), OpenEXR or Radiance HDR into a film. Errors name the file.
pub fn read_image(path: &Path) -> Result<Film> {
    let rgb = decode(path)?.into_rgb32f();
    let (width, height) = rgb.dimensions();
    let pixels = rgb.into_raw().chunks_exact(3).map(|c| Color::new(c[0], c[1], c[2])).collect();
    Ok(Film { width, height, pixels })
}

/// Reads an image as 8-bit RGB, row-major from the top: `(width, height, bytes)`. 16-bit samples are
/// rounded to 8 bits and float samples clamped to [0, 1] first.
pub fn read_rgb8(path: &Path) -> Result<(u32, u32, Vec<u8>)> {
    let rgb = decode(path)?.into_rgb8();
    let (w, h) = rgb.dimensions();
    Ok((w, h, rgb.into_raw()))
}

fn decode(path: &Path) -> Result<DynamicImage> {
    let bytes = crate::input::load_bytes(path)?;
    let mut reader = ImageReader::new(Cursor::new(&bytes[..]));
    if let Ok(format) = ImageFormat::from_path(path) {
        reader.set_format(format);
    }
    let reader = reader.with_guessed_format().map_err(|e| Error::io(path, e))?;
    if reader.format() == Some(ImageFormat::Jpeg) && !super::jpeg::is_whole(&bytes) {
        let msg = "cannot decode image: the JPEG data ends before its end-of-image marker (the file is truncated)";
        return Err(Error::input(Location::file(path), msg));
    }
    reader.decode().map_err(|e| {
        let why = match e {
            // The bytes are already in memory, so a decoder's I/O error is the data's fault, never the
            // disk's: bad input (exit 3), like any other undecodable file.
            image::ImageError::IoError(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => {
                "unexpected end of file (the file is truncated)".to_string()
            }
            other => other.to_string(),
        };
        Error::input(Location::file(path), format!("cannot decode image: {why}"))
    })
}
