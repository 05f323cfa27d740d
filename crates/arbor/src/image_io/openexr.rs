//! OpenEXR images, read with the exr crate as the image crate's `OpenExrDecoder` reads them: the image
//! is the display window of the first flat layer holding R, G and B; its largest resolution level is
//! read, pixels outside the data window are black, A is ignored and other channels skipped. Unlike that
//! decoder, the header is checked before any block is read, and the pixels go straight into one buffer
//! reserved fallibly (the decoder fills a buffer of its own, then copies it).
//!
//! Every header is held to the budget ([`ImageLimits`]) by its display window (the image), its data
//! window (the pixels the file stores, whose blocks are decompressed) and the bytes of all its channels
//! over the data window: at most 16 per pixel of the budget (four float channels), since a header may
//! list thousands of channels over a window within the budget, and each block decompresses all of them.
//! Blocks are decompressed on the calling thread for images under 2^20 pixels (a thread pool per file
//! costs more than it saves there), else in parallel, a few blocks at a time.

use std::cell::Cell;
use std::io::Cursor;
use std::path::Path;

use exr::meta::header::Header;
use exr::meta::MetaData;
use exr::prelude::*;
use image::ColorType;

use super::limits::{try_vec, ImageLimits};
use crate::error::{Error, Location, Result, LIFT_LIMITS};

/// Bytes of all channels of a pixel of the data window, per pixel of the budget.
const BYTES_PER_PIXEL: u64 = 16;

/// Images with at least this many pixels in their data window are decompressed in parallel.
const PARALLEL: u64 = 1 << 20;

/// The pixels of the OpenEXR file `bytes` as native-endian float RGB: `(width, height, Rgb32F, bytes)`.
pub(super) fn decode_rgb(bytes: &[u8], path: &Path, limits: &ImageLimits) -> Result<(u32, u32, ColorType, Vec<u8>)> {
    let bad = |e: exr::error::Error| {
        Error::input(Location::file(path), format!("cannot decode image: not a readable OpenEXR file: {e}"))
    };
    let meta = MetaData::read_from_buffered(Cursor::new(bytes), false).map_err(bad)?;
    for header in &meta.headers {
        check_header(header, path, limits)?;
    }
    let has = |h: &Header, name: &str| h.channels.find_index_of_channel(&Text::from(name)).is_some();
    let Some(header) = meta.headers.iter().find(|h| !h.deep && ["R", "G", "B"].iter().all(|c| has(h, c))) else {
        let msg = "cannot decode image: the OpenEXR file has no flat layer with R, G and B channels";
        return Err(Error::input(Location::file(path), msg));
    };
    let display = header.shared_attributes.display_window;
    let offset = header.own_attributes.layer_position - display.position;
    let (width, height) = (display.size.width(), display.size.height());
    let n = (width as u64).saturating_mul(height as u64).saturating_mul(12);
    let mut storage: Vec<u8> = try_vec(n, width as u32, height as u32, "decode it", path)?;
    storage.resize(n as usize, 0);
    // The reader asks for its storage through a shared closure: it takes the one reserved above.
    let storage = Cell::new(Some(storage));
    let set = move |pixels: &mut Vec<u8>, at: Vec2<usize>, (r, g, b, _a): (f32, f32, f32, f32)| {
        let p = at.to_i32() + offset;
        if p.x() >= 0 && p.y() >= 0 && (p.x() as usize) < width && (p.y() as usize) < height {
            let i = 12 * (p.y() as usize * width + p.x() as usize);
            if let Some(dst) = pixels.get_mut(i..i + 12) {
                for (k, v) in [r, g, b].into_iter().enumerate() {
                    dst[4 * k..4 * k + 4].copy_from_slice(&v.to_ne_bytes());
                }
            }
        }
    };
    let reader = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(|_, _| storage.take().unwrap_or_default(), set)
        .first_valid_layer()
        .all_attributes();
    let small = (header.layer_size.area() as u64) < PARALLEL;
    let reader = if small { reader.non_parallel() } else { reader };
    let image = reader.from_buffered(Cursor::new(bytes)).map_err(bad)?;
    Ok((width as u32, height as u32, ColorType::Rgb32F, image.layer_data.channel_data.pixels))
}

/// Refuses a header whose display window, data window or channel data is above the budget.
fn check_header(header: &Header, path: &Path, limits: &ImageLimits) -> Result<()> {
    let display = header.shared_attributes.display_window.size;
    limits.check_area("image", display.width() as u64, display.height() as u64, path)?;
    let (w, h) = (header.layer_size.width() as u64, header.layer_size.height() as u64);
    limits.check_area("the data window", w, h, path)?;
    let per_pixel = header.channels.bytes_per_pixel as u64;
    let bytes = (w * h).saturating_mul(per_pixel);
    let max = limits.max_pixels.saturating_mul(BYTES_PER_PIXEL);
    if bytes > max {
        let n = header.channels.list.len();
        let msg = format!(
            "the data window {w}x{h} holds {bytes} bytes in {n} channels, more than the limit of {max} \
             ({BYTES_PER_PIXEL} per pixel of the limit); {LIFT_LIMITS}"
        );
        return Err(Error::input(Location::file(path), msg));
    }
    Ok(())
}
