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

/// Images with at least this many pixels in their data windows are decompressed in parallel.
const PARALLEL: u64 = 1 << 20;

/// Whether a file of these headers is worth decompressing on a pool of threads of its own.
pub(crate) fn in_parallel(headers: &[Header]) -> bool {
    headers.iter().map(|h| h.layer_size.area() as u64).sum::<u64>() >= PARALLEL
}

/// Puts the attributes of a single-part OpenEXR file's header (`bytes`, as the exr crate wrote it) in
/// the order of their names: the crate writes custom attributes in a `HashMap`'s order, which changes
/// from one map to the next, so the same image written twice differed in its bytes. The header keeps its
/// length, so the offset table after it stays right. A header it cannot read (multi-part, or cut short)
/// is left as it is.
pub(crate) fn sort_header_attributes(bytes: &mut [u8]) {
    const MULTI_PART: u32 = 0x1000;
    let Some(version) = bytes.get(4..8).map(|v| u32::from_le_bytes([v[0], v[1], v[2], v[3]])) else { return };
    if version & MULTI_PART != 0 {
        return;
    }
    // Each attribute: name, NUL, type name, NUL, a 4-byte little-endian size, then that many bytes; an
    // empty name (a lone NUL) ends the header.
    let (start, mut at, mut spans) = (8, 8, Vec::new());
    let nul = |from: usize| bytes.get(from..)?.iter().position(|&b| b == 0).map(|i| from + i);
    loop {
        match bytes.get(at) {
            None => return,
            Some(0) => break,
            Some(_) => {}
        }
        let Some(name_end) = nul(at) else { return };
        let Some(type_end) = nul(name_end + 1) else { return };
        let Some(size) = bytes.get(type_end + 1..type_end + 5) else { return };
        let end = type_end + 5 + u32::from_le_bytes([size[0], size[1], size[2], size[3]]) as usize;
        if end > bytes.len() {
            return;
        }
        spans.push((at, name_end, end));
        at = end;
    }
    spans.sort_by(|a, b| bytes[a.0..a.1].cmp(&bytes[b.0..b.1]));
    let sorted: Vec<u8> = spans.iter().flat_map(|&(from, _, end)| bytes[from..end].iter().copied()).collect();
    bytes[start..at].copy_from_slice(&sorted);
}

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
    let reader = if in_parallel(&meta.headers) { reader } else { reader.non_parallel() };
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image_io::decode;
    use crate::math::Color;

    /// An EXR of float channels `names` over a data window of `size` at `position` in a `display` frame.
    fn exr(size: (usize, usize), position: (i32, i32), display: (usize, usize), names: &[&str]) -> Vec<u8> {
        let n = size.0 * size.1;
        let sample = |i: usize, k: usize| (i * 10 + k) as f32 * 0.25;
        let channels: Vec<AnyChannel<FlatSamples>> = (names.iter().enumerate())
            .map(|(k, name)| AnyChannel::new(*name, FlatSamples::F32((0..n).map(|i| sample(i, k)).collect())))
            .collect();
        let attributes = LayerAttributes { layer_position: Vec2(position.0, position.1), ..Default::default() };
        let layer = Layer::new(size, attributes, Encoding::SMALL_LOSSLESS, AnyChannels::sort(channels.into()));
        let mut image = Image::from_layer(layer);
        image.attributes.display_window = IntegerBounds::new((0, 0), display);
        let mut bytes = Cursor::new(Vec::new());
        image.write().to_buffered(&mut bytes).unwrap();
        bytes.into_inner()
    }

    #[test]
    fn openexr_reads_a_data_window_inside_its_display_window_as_the_image_crate_does() {
        let bytes = exr((3, 2), (1, 2), (5, 4), &["A", "B", "G", "R", "Z"]);
        let (w, h, ours) = decode::<Color>(&bytes, Path::new("a.exr"), &ImageLimits::DEFAULT).unwrap();
        let theirs = image::load_from_memory(&bytes).unwrap().into_rgb32f();
        assert_eq!(((w, h), theirs.dimensions()), ((5, 4), (5, 4)));
        let ours: Vec<f32> = ours.iter().flat_map(|c| c.to_array()).collect();
        assert!(ours.iter().zip(theirs.as_raw()).all(|(a, b)| a.to_bits() == b.to_bits()));
        // Black outside the data window; inside, pixel (1, 2) is the window's first (B, G, R = channels 1-3).
        assert_eq!(ours[..3 * 11], [0.0; 33]);
        assert_eq!(ours[3 * 11..3 * 12], [0.75, 0.5, 0.25]);
    }

    #[test]
    fn openexr_headers_are_held_to_the_budget_by_both_windows_and_the_channel_bytes() {
        let limits = ImageLimits { max_pixels: 16 };
        let rgb = ["B", "G", "R"];
        let e = |bytes: &[u8]| decode::<u8>(bytes, Path::new("a.exr"), &limits).unwrap_err().to_string();
        assert!(
            e(&exr((2, 2), (0, 0), (5, 4), &rgb)).starts_with("a.exr: image 5x4 has 20 pixels, more than the limit")
        );
        assert!(e(&exr((5, 4), (0, 0), (2, 2), &rgb)).starts_with("a.exr: the data window 5x4 has 20 pixels, more"));
        assert_eq!(
            e(&exr((4, 4), (0, 0), (4, 4), &["A", "B", "C", "G", "R"])),
            "a.exr: the data window 4x4 holds 320 bytes in 5 channels, more than the limit of 256 (16 per pixel of \
             the limit); --no-limits lifts the limits"
        );
        // Four float channels: 16 bytes a pixel, the most the budget takes.
        decode::<u8>(&exr((4, 4), (0, 0), (4, 4), &["A", "B", "G", "R"]), Path::new("a.exr"), &limits).unwrap();
    }
}
