//! Writing a film: the format follows the extension, and the file appears whole or not at all.
//!
//! The encoded image is built in memory first (an encoder failure never touches the disk), then written to
//! `.<name>.<pid>.<n>.tmp` next to the target, flushed to disk and renamed over the target. A rename within
//! one directory is atomic on POSIX and replaces the target on Windows, so readers see either the old image
//! or the new one. On any failure the temporary file is removed, and the error names the target (the
//! temporary file is an implementation detail the user never asked for).
//!
//! An image with a tone-mapped PNG beside it is one output: both files are written to temporary files
//! before either is renamed, and should the second rename fail, the first target gets its previous
//! contents back (kept meanwhile as a hard link, `.<name>.<pid>.<n>.old`) or is removed if it had none,
//! so a failed run leaves the old pair or nothing, never a new image beside an old or missing PNG.
//! [`write_files`] does the same for any set of encoded files ([`encode_outputs`]): `arbor render`
//! writes all its cameras' images and its statistics as one set, after the last render.
//!
//! The temporary names keep at most [`NAME_KEPT`] bytes of the target's name, so they fit the file
//! system's limit on a name (255 bytes on the usual ones) whenever the target's name does.

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
    write_atomic(path, &encoded(path, film)?)
}

/// The bytes of `film` in the format of `path`'s extension.
fn encoded(path: &Path, film: &Film) -> Result<Vec<u8>> {
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
    encode(film, format).map_err(|e| Error::Invalid(format!("cannot encode {}: {e}", path.display())))
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

/// Writes a camera's image. `film` holds display values, in which one unit of the scene's radiance is
/// `unit` (the scene's radiance scale: 1/255 for METU files; 1 for a debug view). An 8-bit format gets
/// the film as it is, or tone-mapped with a `tonemap`; a high-dynamic-range format gets radiance in the
/// scene's own units (the film over `unit`, as the course's official EXRs hold it), plus with a
/// `tonemap` the tone-mapped PNG of the film beside it ([`tone_mapped_beside`]), replacing a file of that
/// name. Returns the files written: all of them, atomically, or none (see the module documentation).
pub fn write_outputs(path: &Path, film: &Film, unit: f32, tonemap: Option<&Tonemap>) -> Result<Vec<PathBuf>> {
    let files = encode_outputs(path, film, unit, tonemap)?;
    write_files(&files)?;
    Ok(files.into_iter().map(|(p, _)| p).collect())
}

/// The files [`write_outputs`] writes, encoded in memory: the image, and the PNG beside an HDR one.
pub fn encode_outputs(
    path: &Path,
    film: &Film,
    unit: f32,
    tonemap: Option<&Tonemap>,
) -> Result<Vec<(PathBuf, Vec<u8>)>> {
    if is_hdr_path(path) {
        let image = (path.to_path_buf(), encoded(path, &in_radiance(film, unit))?);
        let Some(tm) = tonemap else { return Ok(vec![image]) };
        let png = tone_mapped_beside(path);
        let preview = encoded(&png, &tm.apply(film))?;
        return Ok(vec![image, (png, preview)]);
    }
    let bytes = match tonemap {
        Some(tm) => encoded(path, &tm.apply(film))?,
        None => encoded(path, film)?,
    };
    Ok(vec![(path.to_path_buf(), bytes)])
}

/// `film` over `unit`: display values back in the scene's radiance units.
fn in_radiance(film: &Film, unit: f32) -> std::borrow::Cow<'_, Film> {
    if unit == 1.0 {
        return std::borrow::Cow::Borrowed(film);
    }
    let pixels = film.pixels.iter().map(|&c| c / unit).collect();
    std::borrow::Cow::Owned(Film { width: film.width, height: film.height, pixels })
}

/// Writes every `(path, bytes)` of `files` atomically, all or none: a failure leaves every target as
/// it was (see the module documentation). The paths must be distinct.
pub fn write_files(files: &[(PathBuf, Vec<u8>)]) -> Result<()> {
    let set: Vec<(&Path, &[u8])> = files.iter().map(|(p, b)| (p.as_path(), b.as_slice())).collect();
    write_atomic_set(&set)
}

/// Writes `bytes` to a fresh temporary file beside `path` and renames it over `path`.
pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic_set(&[(path, bytes)])
}

/// Writes every `(path, bytes)` of `files` atomically, or none of them: the renames start once every
/// temporary file is on disk, and a failed rename undoes those before it.
fn write_atomic_set(files: &[(&Path, &[u8])]) -> Result<()> {
    let mut temps = Vec::with_capacity(files.len());
    for (path, bytes) in files {
        match write_temp(path, bytes) {
            Ok(tmp) => temps.push(tmp),
            Err(e) => {
                remove_all(&temps);
                return Err(e);
            }
        }
    }
    // Each renamed target and the link that keeps its previous contents, if it had any. The last
    // rename has nothing after it to fail, so its target needs none.
    let mut renamed: Vec<(&Path, Option<PathBuf>)> = Vec::with_capacity(files.len());
    for (i, ((path, _), tmp)) in files.iter().zip(&temps).enumerate() {
        let previous = if i + 1 < files.len() { keep_previous(path) } else { None };
        if let Err(e) = fs::rename(tmp, path) {
            // Best effort, as for one file: the rename's error is the one worth reporting.
            remove_all(&temps[i..]);
            remove_all(previous.as_slice());
            for (done, previous) in renamed.into_iter().rev() {
                let _ = match previous {
                    Some(p) => fs::rename(p, done),
                    None => fs::remove_file(done),
                };
            }
            return Err(Error::io(path, e));
        }
        renamed.push((path, previous));
    }
    let kept: Vec<PathBuf> = renamed.into_iter().filter_map(|(_, p)| p).collect();
    remove_all(&kept);
    Ok(())
}

/// Removes the files, as far as possible: used on paths this module created, while another error is
/// being reported or after success.
fn remove_all(files: &[PathBuf]) {
    for f in files {
        let _ = fs::remove_file(f);
    }
}

/// A hard link to the file (or symbolic link) at `path` under a fresh name beside it; `None` when there
/// is none or the file system cannot link, in which case undoing a write removes the file instead.
fn keep_previous(path: &Path) -> Option<PathBuf> {
    if fs::symlink_metadata(path).ok()?.is_dir() {
        return None;
    }
    loop {
        let link = fresh_name(path, "old");
        match fs::hard_link(path, &link) {
            Ok(()) => return Some(link),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(_) => return None,
        }
    }
}

/// Writes `bytes` to a new temporary file beside `path` (creating the folder when missing) and flushes
/// it to disk; errors name `path`.
fn write_temp(path: &Path, bytes: &[u8]) -> Result<PathBuf> {
    let dir = folder_of(path);
    fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
    let (tmp, mut file) = create_temp(path)?;
    let written = file.write_all(bytes).and_then(|()| file.sync_all());
    drop(file);
    match written {
        Ok(()) => Ok(tmp),
        Err(e) => {
            let _ = fs::remove_file(&tmp);
            Err(Error::io(path, e))
        }
    }
}

fn folder_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// The most bytes of a target's name a temporary name keeps: with the dot, a 10-digit pid, a 20-digit
/// count and the extension it stays under 255 bytes.
pub const NAME_KEPT: usize = 200;

/// `.<name>.<pid>.<n>.<ext>` beside `target`, unique per process and call, so parallel writers never
/// share one; `<name>` is the target's name cut to [`NAME_KEPT`] bytes (at a character boundary).
fn fresh_name(target: &Path, ext: &str) -> PathBuf {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let mut name = target.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "image".to_string());
    let cut = (0..=NAME_KEPT.min(name.len())).rev().find(|&i| name.is_char_boundary(i)).unwrap_or(0);
    name.truncate(cut);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    folder_of(target).join(format!(".{name}.{}.{n}.{ext}", std::process::id()))
}

/// A new temporary file named after the target.
fn create_temp(target: &Path) -> Result<(PathBuf, fs::File)> {
    loop {
        let tmp = fresh_name(target, "tmp");
        match fs::OpenOptions::new().write(true).create_new(true).open(&tmp) {
            Ok(f) => return Ok((tmp, f)),
            // A leftover from a killed run with the same pid: take the next number.
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(Error::io(target, e)),
        }
    }
}
