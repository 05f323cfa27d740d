//! Writing a film: the format follows the extension, and the file appears whole or not at all.
//!
//! The encoded image is built in memory first (an encoder failure never touches the disk), then written to
//! `.<name>.<pid>.<n>.tmp` next to the target, flushed to disk and renamed over the target. A rename within
//! one directory is atomic on POSIX and replaces the target on Windows, so readers see either the old image
//! or the new one. On any failure the temporary file is removed, and the error names the target (the
//! temporary file is an implementation detail the user never asked for).

use std::fs;
use std::io::{Cursor, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use image::codecs::hdr::HdrEncoder;
use image::codecs::jpeg::JpegEncoder;
use image::codecs::png::PngEncoder;
use image::codecs::pnm::{PnmEncoder, PnmSubtype, SampleEncoding};
use image::{ExtendedColorType, ImageEncoder};

use crate::error::{Error, Result};
use crate::film::Film;
use crate::tonemap::Tonemap;

/// The extensions [`write_image`] understands (compared case-insensitively).
pub const SUPPORTED_WRITE_EXTENSIONS: &[&str] = &["png", "ppm", "exr", "hdr", "jpg", "jpeg"];

/// JPEG quality (of 100): high enough that the 8-bit quantisation, not the compression, dominates.
const JPEG_QUALITY: u8 = 95;

#[derive(Clone, Copy)]
enum Format {
    /// 8-bit RGB, through the image crate's encoders.
    Rgb8(Rgb8),
    /// 32-bit float RGB, through the exr crate.
    Exr,
    /// Radiance RGBE, through the image crate.
    Hdr,
}

#[derive(Clone, Copy)]
enum Rgb8 {
    Png,
    Ppm,
    Jpeg,
}

/// Writes `film` to `path`, choosing the format by the extension (case-insensitive): `png` (8-bit RGB),
/// `ppm` (binary P6, 8-bit), `jpg`/`jpeg` (8-bit, quality 95, from the same 8-bit values as PNG) or
/// `exr` (32-bit float RGB, values as they are, including > 1 and < 0) or `hdr` (Radiance RGBE, which
/// holds no negative values: those become 0).
///
/// The parent directory is created when missing. The write is atomic: on failure an existing file at
/// `path` is left untouched and no temporary file remains.
pub fn write_image(path: &Path, film: &Film) -> Result<()> {
    let format = format_of(path)?;
    let expected = film.width as usize * film.height as usize;
    if film.pixels.len() != expected || expected == 0 {
        return Err(Error::Invalid(format!(
            "cannot write {}: the film is {}x{} but holds {} pixels",
            path.display(),
            film.width,
            film.height,
            film.pixels.len()
        )));
    }
    let bytes = encode(film, format).map_err(|e| Error::Invalid(format!("cannot encode {}: {e}", path.display())))?;
    write_atomic(path, &bytes)
}

fn format_of(path: &Path) -> Result<Format> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("png") => Ok(Format::Rgb8(Rgb8::Png)),
        Some("ppm") => Ok(Format::Rgb8(Rgb8::Ppm)),
        Some("exr") => Ok(Format::Exr),
        Some("hdr") => Ok(Format::Hdr),
        Some("jpg" | "jpeg") => Ok(Format::Rgb8(Rgb8::Jpeg)),
        other => {
            let named = match other {
                Some(e) => format!("unknown image extension \".{e}\""),
                None => "no image extension".to_string(),
            };
            Err(Error::Invalid(format!(
                "cannot write {}: {named}; supported: {}",
                path.display(),
                SUPPORTED_WRITE_EXTENSIONS.join(", ")
            )))
        }
    }
}

fn encode(film: &Film, format: Format) -> std::result::Result<Vec<u8>, String> {
    match format {
        Format::Exr => encode_exr(film).map_err(|e| e.to_string()),
        Format::Hdr => encode_hdr(film).map_err(|e| e.to_string()),
        Format::Rgb8(f) => encode_rgb8(film, f).map_err(|e| e.to_string()),
    }
}

/// 32-bit float RGB through the exr crate, the writer of the farm's partial EXRs too. Its blocks are
/// compressed in parallel; increasing line order makes it write them sorted, so the same pixels give
/// the same file bytes on every run (the crate's default order is whichever block finished first).
fn encode_exr(film: &Film) -> exr::error::Result<Vec<u8>> {
    use exr::prelude::{Encoding, Image, LineOrder, SpecificChannels, Vec2, WritableImage};
    let w = film.width as usize;
    let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
        let c = film.pixels[p.y() * w + p.x()];
        (c.x, c.y, c.z)
    });
    let mut out = Cursor::new(Vec::new());
    let encoding = Encoding { line_order: LineOrder::Increasing, ..Encoding::FAST_LOSSLESS };
    Image::from_encoded_channels((w, film.height as usize), encoding, channels).write().to_buffered(&mut out)?;
    Ok(out.into_inner())
}

fn encode_hdr(film: &Film) -> image::ImageResult<Vec<u8>> {
    let positive = |v: f32| if v > 0.0 { v.min(f32::MAX) } else { 0.0 };
    let pixels: Vec<image::Rgb<f32>> =
        film.pixels.iter().map(|c| image::Rgb([positive(c.x), positive(c.y), positive(c.z)])).collect();
    let mut out = Vec::new();
    HdrEncoder::new(&mut out).encode(&pixels, film.width as usize, film.height as usize)?;
    Ok(out)
}

fn encode_rgb8(film: &Film, format: Rgb8) -> image::ImageResult<Vec<u8>> {
    let (w, h) = (film.width, film.height);
    let mut out = Cursor::new(Vec::new());
    match format {
        Rgb8::Png => PngEncoder::new(&mut out).write_image(&film.to_rgb8(), w, h, ExtendedColorType::Rgb8)?,
        Rgb8::Ppm => PnmEncoder::new(&mut out).with_subtype(PnmSubtype::Pixmap(SampleEncoding::Binary)).write_image(
            &film.to_rgb8(),
            w,
            h,
            ExtendedColorType::Rgb8,
        )?,
        Rgb8::Jpeg => JpegEncoder::new_with_quality(&mut out, JPEG_QUALITY).write_image(
            &film.to_rgb8(),
            w,
            h,
            ExtendedColorType::Rgb8,
        )?,
    }
    Ok(out.into_inner())
}

/// True when `path` names a high-dynamic-range format (`exr`, `hdr`).
pub fn is_hdr_path(path: &Path) -> bool {
    matches!(format_of(path), Ok(Format::Exr | Format::Hdr))
}

/// The tone-mapped PNG written beside the high-dynamic-range image `path` (the course's rule).
pub fn tone_mapped_beside(path: &Path) -> PathBuf {
    path.with_extension("png")
}

/// Writes a camera's image: `film` as it is to `path`, except that with a `tonemap` an 8-bit format gets
/// the tone-mapped film, and a high-dynamic-range one gets the film as it is plus the tone-mapped PNG
/// beside it ([`tone_mapped_beside`]). Returns the files written, each written atomically.
pub fn write_outputs(path: &Path, film: &Film, tonemap: Option<&Tonemap>) -> Result<Vec<PathBuf>> {
    let Some(tm) = tonemap else {
        write_image(path, film)?;
        return Ok(vec![path.to_path_buf()]);
    };
    if is_hdr_path(path) {
        write_image(path, film)?;
        let png = tone_mapped_beside(path);
        write_image(&png, &tm.apply(film))?;
        Ok(vec![path.to_path_buf(), png])
    } else {
        write_image(path, &tm.apply(film))?;
        Ok(vec![path.to_path_buf()])
    }
}

/// Writes `bytes` to a fresh temporary file beside `path` and renames it over `path`.
pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
    let (tmp, mut file) = create_temp(&dir, path)?;
    let written = file.write_all(bytes).and_then(|()| file.sync_all()).map_err(|e| Error::io(path, e));
    drop(file);
    let renamed = written.and_then(|()| fs::rename(&tmp, path).map_err(|e| Error::io(path, e)));
    if renamed.is_err() {
        // Best effort: the original error is the one worth reporting.
        let _ = fs::remove_file(&tmp);
    }
    renamed
}

/// A new file named after the target, unique per process and call, so parallel writers never share one.
fn create_temp(dir: &Path, target: &Path) -> Result<(PathBuf, fs::File)> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = target.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "image".to_string());
    loop {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let tmp = dir.join(format!(".{name}.{}.{n}.tmp", std::process::id()));
        match fs::OpenOptions::new().write(true).create_new(true).open(&tmp) {
            Ok(f) => return Ok((tmp, f)),
            // A leftover from a killed run with the same pid: take the next number.
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(Error::io(target, e)),
        }
    }
}
