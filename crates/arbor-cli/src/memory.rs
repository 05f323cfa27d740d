//! Memory for an image, asked for before its render starts: a render that cannot get its buffers is
//! refused with "not enough memory for a WxH image (N GiB)" (exit 4) instead of dying of an allocation
//! failure at its end with the work lost.
//!
//! The renderer allocates its own large buffers fallibly (the film and the sums before tracing, each
//! tile's sums as it goes: `arbor::Error::OutOfMemory`); this reserves their total peak once, before
//! the render, and gives it back: under an address-space limit (`ulimit -v`, a batch system's memory
//! limit) or beyond what the system will commit, the reservation fails where the render would have,
//! and the message gives the whole image's need rather than one buffer's. Per pixel of the window: the exact sample sums (48 bytes: three i128), the
//! film in linear RGB (12 bytes; for a plain render one of the full frame too, as debug overlays are
//! drawn in frame coordinates), and the encoded output with its 8-bit or float copy (at most 28 bytes).
//! A run of several cameras keeps each image's encoded files until the last render ([`held`]), so its
//! peak ([`reserve_run`]) is reserved before the first.

use std::path::{Path, PathBuf};

use arbor::scene::CameraDesc;

use crate::Failure;

/// Bytes of one pixel's exact sample sums.
const SUMS: u64 = 48;
/// Bytes of one pixel of the film.
const FILM: u64 = 12;
/// Bytes per pixel, at most, of the quantised or float copy and the encoded file.
const ENCODE: u64 = 28;

/// The bytes a render of `window` of a `width` x `height` frame needs at its peak: a film (`partial`
/// false) or a partial EXR of sums (`partial` true).
pub fn need(width: u32, height: u32, window: (u32, u32, u32, u32), partial: bool) -> u64 {
    let win = u64::from(window.2 - window.0) * u64::from(window.3 - window.1);
    let frame = u64::from(width) * u64::from(height);
    if partial {
        win * (2 * SUMS + ENCODE)
    } else {
        win * (SUMS + FILM + ENCODE) + frame * FILM
    }
}

/// The bytes the encoded files `files` of an image of `window` take at most while they wait for the
/// run's end (`arbor render` writes every camera's files together): per pixel, 13 for an EXR (12 of
/// float RGB, and its compression can grow data a little), 5 for Radiance HDR (4), 4 for an 8-bit
/// format (3), the excess covering headers and the compressors' worst cases.
pub fn held<'a>(window: (u32, u32, u32, u32), files: impl IntoIterator<Item = &'a Path>) -> u64 {
    let pixels = u64::from(window.2 - window.0) * u64::from(window.3 - window.1);
    let per_pixel = |f: &Path| match f.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("exr") => 13,
        Some("hdr") => 5,
        _ => 4,
    };
    files.into_iter().map(|f| pixels * per_pixel(f) + 4096).sum()
}

/// Reserves and releases the memory of [`need`], or says that there is not enough.
pub fn reserve_for(width: u32, height: u32, window: (u32, u32, u32, u32), partial: bool) -> Result<(), Failure> {
    let bytes = need(width, height, window, partial);
    if !reserve(bytes) {
        let (w, h) = (window.2 - window.0, window.3 - window.1);
        return Err(Failure::OutOfMemory(format!("not enough memory for a {w}x{h} image ({})", gib(bytes))));
    }
    Ok(())
}

/// Reserves, before the first render of `cameras` (writing `targets`, with the PNG beside an HDR image
/// when `preview`, over the window `crop`), each image's memory and the run's peak: each render runs
/// beside the encoded files of those before it ([`held`]). Says which does not fit, if one does not.
pub fn reserve_run(
    cameras: &[&CameraDesc],
    targets: &[PathBuf],
    crop: Option<(u32, u32, u32, u32)>,
    preview: bool,
) -> Result<(), Failure> {
    if cameras.len() < 2 {
        return Ok(());
    }
    let mut images = Vec::with_capacity(cameras.len());
    for (cam, target) in cameras.iter().zip(targets) {
        let window = arbor::render::crop_window(crop, cam.width, cam.height);
        reserve_for(cam.width, cam.height, window, false)?;
        let files = crate::outputs::files_written(target, preview);
        images.push((need(cam.width, cam.height, window, false), held(window, files.iter().map(PathBuf::as_path))));
    }
    let peak = peak(&images);
    if !reserve(peak) {
        return Err(Failure::OutOfMemory(format!(
            "not enough memory for the {} images of this run ({} at the peak: each is kept, encoded, until the last \
             is rendered, and all are written together); --camera ID renders one at a time",
            images.len(),
            gib(peak)
        )));
    }
    Ok(())
}

/// The most bytes a run of images needing `(render, held)` bytes each holds at once.
fn peak(images: &[(u64, u64)]) -> u64 {
    let mut before = 0u64;
    let mut peak = 0u64;
    for &(render, held) in images {
        peak = peak.max(before.saturating_add(render));
        before = before.saturating_add(held);
    }
    peak
}

/// True when `bytes` could be allocated (they are released at once).
fn reserve(bytes: u64) -> bool {
    let mut probe: Vec<u8> = Vec::new();
    usize::try_from(bytes).ok().and_then(|n| probe.try_reserve_exact(n).ok()).is_some()
}

fn gib(bytes: u64) -> String {
    format!("{:.1} GiB", bytes as f64 / (1u64 << 30) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn memory_need_counts_the_window_and_the_frame() {
        assert_eq!(need(10, 10, (0, 0, 10, 10), false), 100 * (48 + 12 + 28) + 100 * 12);
        assert_eq!(need(10, 10, (0, 0, 5, 2), true), 10 * (96 + 28));
    }

    #[test]
    fn memory_peak_of_a_run_holds_the_earlier_images_encoded() {
        // The third render runs beside the first two images: 15 + 70 is more than the first render's 80.
        assert_eq!(peak(&[(80, 10), (50, 5), (70, 1)]), 85);
        assert_eq!(peak(&[(1, u64::MAX), (1, 1)]), u64::MAX, "saturates");
        let png = held((0, 0, 10, 10), [Path::new("a.png")]);
        let exr = held((0, 0, 10, 10), [Path::new("a.exr"), Path::new("a.png")]);
        assert_eq!((png, exr), (400 + 4096, 1300 + 400 + 2 * 4096));
    }

    #[test]
    fn memory_reservation_beyond_any_machine_fails_with_the_size() {
        let Err(Failure::OutOfMemory(msg)) = reserve_for(4_000_000, 4_000_000, (0, 0, 4_000_000, 4_000_000), false)
        else {
            panic!("16 terapixels reserved");
        };
        assert_eq!(msg, "not enough memory for a 4000000x4000000 image (1490116.1 GiB)");
        assert!(reserve_for(64, 64, (0, 0, 64, 64), false).is_ok());
    }
}
