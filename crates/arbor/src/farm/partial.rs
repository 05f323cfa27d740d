//! A slice's result on disk: an OpenEXR file that any EXR viewer opens, carrying what `arbor merge`
//! needs to rebuild the exact single-process image.
//!
//! - Display window: the full frame (`0,0 .. width,height`); data window: the slice's pixels.
//! - Channels `R`, `G`, `B` (float): the slice's own mean, in the scene's radiance units like every HDR
//!   image Arbor writes (for looking at it); `W` (uint): the samples per pixel this file holds (its
//!   weight); `sumR0..sumR3`, `sumG0..`, `sumB0..` (uint): each channel's exact fixed-point sample sum
//!   ([`crate::accum`]), an `i128` as four little-endian 32-bit limbs.
//! - Header attributes: `arbor.render` (identity of the render: scene, camera and the options that
//!   change pixels), `arbor.camera`, `arbor.spp` (samples per pixel of the full image),
//!   `arbor.sampleStart` and `arbor.sampleEnd` (the samples held, `start..end`), `arbor.scale` (radiance
//!   scale applied at the end), and for a camera with a tone mapping `arbor.tonemap` (the operator) with
//!   `arbor.tonemapKey`, `arbor.tonemapBurn`, `arbor.tonemapSaturation`, `arbor.tonemapGamma` and
//!   `arbor.tonemapUnit`, so that
//!   the merged image is written as the single-process render writes it.
//!
//! Written atomically like every image; read back with every field checked, errors naming the file.
//! Before any pixel is read, the header is held to a budget: the frame (display window) and the slice
//! (data window) at most the limit's pixels, at most 64 bytes a pixel (the sixteen 32-bit channels
//! above); the channels the exr crate then allocates are reserved first, so that a file too large for
//! the memory is an error, not an abort.

use std::io::Cursor;
use std::path::Path;

use exr::prelude::*;

use crate::accum::SampleSum;
use crate::error::{Error, Location, Result};
use crate::image_io::ImageLimits;
use crate::render::RenderSums;
use crate::tonemap::{Operator, Tonemap};

/// A partial image: the sums of one slice and where they belong.
#[derive(Debug, Clone, PartialEq)]
pub struct Partial {
    /// The render's identity: partials merge only with partials of the same identity.
    pub identity: String,
    /// The camera's id (informative; part of the identity).
    pub camera: String,
    /// The camera's tone mapping, applied when the merged image is written.
    pub tonemap: Option<Tonemap>,
    /// Frame, window, sample range, scale and the sums.
    pub sums: RenderSums,
}

const CHANNELS: [&str; 3] = ["R", "G", "B"];
const TONEMAP_FIELDS: [&str; 5] =
    ["arbor.tonemapKey", "arbor.tonemapBurn", "arbor.tonemapSaturation", "arbor.tonemapGamma", "arbor.tonemapUnit"];

/// Writes `part` to `path` (atomically: a temporary file renamed over the target).
pub fn write_partial(path: &Path, part: &Partial) -> Result<()> {
    crate::image_io::write::write_atomic(path, &encode_partial(path, part)?)
}

/// The bytes [`write_partial`] writes to `path` (named in a failure to encode).
pub fn encode_partial(path: &Path, part: &Partial) -> Result<Vec<u8>> {
    let s = &part.sums;
    let (x0, y0, x1, y1) = s.window;
    let count = s.samples.1 - s.samples.0;
    let mut channels: Vec<AnyChannel<FlatSamples>> = Vec::new();
    for (c, name) in CHANNELS.iter().enumerate() {
        let mean = s.sums.iter().map(|p| p.value(1.0, count).to_array()[c]).collect();
        channels.push(AnyChannel::new(*name, FlatSamples::F32(mean)));
        for limb in 0..4 {
            let bits = s.sums.iter().map(|p| (p.0[c] as u128 >> (32 * limb)) as u32).collect();
            channels.push(AnyChannel::new(format!("sum{name}{limb}").as_str(), FlatSamples::U32(bits)));
        }
    }
    channels.push(AnyChannel::new("W", FlatSamples::U32(vec![count; s.sums.len()])));
    let mut attrs = LayerAttributes { layer_position: Vec2(x0 as i32, y0 as i32), ..Default::default() };
    let text = |v: &str| AttributeValue::Text(Text::new_or_none(v).unwrap_or_else(|| Text::from("?")));
    attrs.other.insert(Text::from("arbor.render"), text(&part.identity));
    attrs.other.insert(Text::from("arbor.camera"), text(&part.camera));
    attrs.other.insert(Text::from("arbor.spp"), AttributeValue::I32(s.spp as i32));
    attrs.other.insert(Text::from("arbor.sampleStart"), AttributeValue::I32(s.samples.0 as i32));
    attrs.other.insert(Text::from("arbor.sampleEnd"), AttributeValue::I32(s.samples.1 as i32));
    attrs.other.insert(Text::from("arbor.scale"), AttributeValue::F32(s.scale));
    if let Some(t) = &part.tonemap {
        let Operator::Photographic = t.operator;
        attrs.other.insert(Text::from("arbor.tonemap"), text("Photographic"));
        for (key, v) in TONEMAP_FIELDS.iter().zip([t.key, t.burn_percent, t.saturation, t.gamma, t.unit]) {
            attrs.other.insert(Text::from(*key), AttributeValue::F32(v));
        }
    }
    let size = ((x1 - x0) as usize, (y1 - y0) as usize);
    let layer = Layer::new(size, attrs, Encoding::SMALL_LOSSLESS, AnyChannels::sort(channels.into()));
    let mut image = Image::from_layer(layer);
    image.attributes.display_window = IntegerBounds::new((0, 0), (s.frame.0 as usize, s.frame.1 as usize));
    let mut bytes = Cursor::new(Vec::new());
    image
        .write()
        .to_buffered(&mut bytes)
        .map_err(|e| Error::Invalid(format!("cannot encode {}: {e}", path.display())))?;
    let mut bytes = bytes.into_inner();
    // The same partial, the same bytes (the attributes come out of a HashMap).
    crate::image_io::sort_exr_header(&mut bytes);
    Ok(bytes)
}

/// Bytes of a pixel of a partial: the 16 channels of 4 bytes each.
const PIXEL_BYTES: usize = 4 * (CHANNELS.len() * 5 + 1);

/// Reads a partial image written by [`write_partial`], its frame and window held to `limits` (those of
/// an image `render` may write: [`crate::scene::SceneLimits::rendered`]).
pub fn read_partial(path: &Path, limits: &ImageLimits) -> Result<Partial> {
    decode_partial(&crate::input::load_bytes(path)?, path, limits)
}

/// [`read_partial`] of the file `bytes`, named `path` in errors.
pub fn decode_partial(bytes: &[u8], path: &Path, limits: &ImageLimits) -> Result<Partial> {
    let bad = |msg: String| Error::input(Location::file(path), msg);
    let meta = exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), false)
        .map_err(|e| bad(format!("not a readable OpenEXR file: {e}")))?;
    let not_partial = || bad("not a partial image of `arbor render` (no arbor.render attribute)".into());
    if !meta.headers.iter().any(|h| h.own_attributes.other.contains_key(&Text::from("arbor.render"))) {
        return Err(not_partial());
    }
    for header in &meta.headers {
        // Tiles (which the exr crate mixes up across resolution levels when a block claims a level the
        // header has not) are never in a partial.
        if header.blocks != exr::meta::BlockDescription::ScanLines || header.deep {
            return Err(bad(
                "not a partial image of `arbor render` (it is tiled or deep, a partial is flat scan lines)".into(),
            ));
        }
        let frame = header.shared_attributes.display_window.size;
        limits.check_area("the frame", frame.width() as u64, frame.height() as u64, path)?;
        let (w, h) = (header.layer_size.width(), header.layer_size.height());
        limits.check_area("the data window", w as u64, h as u64, path)?;
        let per_pixel = header.channels.bytes_per_pixel;
        if per_pixel > PIXEL_BYTES {
            let n = header.channels.list.len();
            return Err(bad(format!(
                "not a partial image of `arbor render` ({n} channels of {per_pixel} bytes a pixel, more than a \
                 partial's {PIXEL_BYTES})"
            )));
        }
        // Reserved and given back: the exr crate allocates the channels itself.
        let need = (w as u64).saturating_mul(h as u64).saturating_mul(per_pixel as u64);
        drop(crate::image_io::try_vec::<u8>(need, w as u32, h as u32, "read it", path)?);
    }
    // Pedantic: a partial is Arbor's own file, and written by the same crate.
    let reader = read().no_deep_data().largest_resolution_level().all_channels().first_valid_layer().all_attributes();
    let reader = reader.pedantic();
    let reader = if crate::image_io::exr_in_parallel(&meta.headers) { reader } else { reader.non_parallel() };
    let image =
        reader.from_buffered(Cursor::new(bytes)).map_err(|e| bad(format!("not a readable OpenEXR file: {e}")))?;
    let layer = &image.layer_data;
    let a = &layer.attributes.other;
    let text = |k: &str| match a.get(&Text::from(k)) {
        Some(AttributeValue::Text(t)) => Some(t.to_string()),
        _ => None,
    };
    let int = |k: &str| match a.get(&Text::from(k)) {
        Some(AttributeValue::I32(v)) if *v >= 0 => Ok(*v as u32),
        _ => Err(bad(format!("attribute {k} is missing or not a non-negative integer"))),
    };
    let identity = text("arbor.render").ok_or_else(not_partial)?;
    let camera = text("arbor.camera").unwrap_or_default();
    let (spp, k0, k1) = (int("arbor.spp")?, int("arbor.sampleStart")?, int("arbor.sampleEnd")?);
    if !(k0 < k1 && k1 <= spp) {
        return Err(bad(format!("sample range {k0}..{k1} is not inside 0..{spp}")));
    }
    let scale = match a.get(&Text::from("arbor.scale")) {
        Some(AttributeValue::F32(v)) => *v,
        _ => return Err(bad("attribute arbor.scale is missing or not a float".into())),
    };
    let float = |k: &str| match a.get(&Text::from(k)) {
        Some(AttributeValue::F32(v)) if v.is_finite() => Ok(*v),
        _ => Err(bad(format!("attribute {k} is missing or not a finite float"))),
    };
    let tonemap = match text("arbor.tonemap").as_deref() {
        None => None,
        Some("Photographic") => {
            let [key, burn_percent, saturation, gamma, unit] = [0, 1, 2, 3, 4].map(|i| float(TONEMAP_FIELDS[i]));
            let (key, burn_percent, saturation, gamma, unit) = (key?, burn_percent?, saturation?, gamma?, unit?);
            Some(Tonemap { operator: Operator::Photographic, key, burn_percent, saturation, gamma, unit })
        }
        Some(other) => return Err(bad(format!("unknown tone mapping operator '{other}' in arbor.tonemap"))),
    };
    let dw = image.attributes.display_window;
    let (pos, size) = (layer.attributes.layer_position, layer.size);
    let frame = (dw.size.0 as u32, dw.size.1 as u32);
    let (x0, y0) = (pos.0.max(0) as u32, pos.1.max(0) as u32);
    let window = (x0, y0, x0 + size.0 as u32, y0 + size.1 as u32);
    if dw.position != Vec2(0, 0) {
        let (x, y) = (dw.position.0, dw.position.1);
        return Err(bad(format!("the display window starts at ({x}, {y}), not at (0, 0) as a frame does")));
    }
    if pos.0 < 0 || pos.1 < 0 || window.2 > frame.0 || window.3 > frame.1 {
        return Err(bad(format!(
            "the data window ({} x {} pixels at ({}, {})) is not inside the {} x {} frame",
            size.0, size.1, pos.0, pos.1, frame.0, frame.1
        )));
    }
    let n = size.0 * size.1;
    let mut sums = crate::film::try_filled(SampleSum::default(), size.0 as u32, size.1 as u32)?;
    let channel = |name: &str| -> Result<&[u32]> {
        match layer.channel_data.list.iter().find(|c| c.name.to_string() == name).map(|c| &c.sample_data) {
            Some(FlatSamples::U32(v)) if v.len() == n => Ok(v),
            _ => Err(bad(format!("channel {name} is missing or not {n} unsigned integers"))),
        }
    };
    if let Some(i) = channel("W")?.iter().position(|&w| w != k1 - k0) {
        return Err(bad(format!("weight W of pixel {i} of the window is not {} (samples {k0}..{k1})", k1 - k0)));
    }
    for (c, name) in CHANNELS.iter().enumerate() {
        for limb in 0..4 {
            for (s, &bits) in sums.iter_mut().zip(channel(&format!("sum{name}{limb}"))?) {
                s.0[c] = (s.0[c] as u128 | (bits as u128) << (32 * limb)) as i128;
            }
        }
    }
    let sums = RenderSums { frame, window, spp, samples: (k0, k1), scale, sums };
    Ok(Partial { identity, camera, tonemap, sums })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn partial_in_tiles_is_refused_before_its_blocks_are_read() {
        let mut attributes = LayerAttributes::default();
        attributes.other.insert(Text::from("arbor.render"), AttributeValue::Text(Text::from("x")));
        let channels = SpecificChannels::rgb(|_: Vec2<usize>| (0.5f32, 0.5f32, 0.5f32));
        let layer = Layer::new((2, 2), attributes, Encoding::FAST_LOSSLESS, channels);
        let mut bytes = Cursor::new(Vec::new());
        Image::from_layer(layer).write().to_buffered(&mut bytes).unwrap();
        let e = decode_partial(bytes.get_ref(), Path::new("t.exr"), &ImageLimits::DEFAULT).unwrap_err();
        let msg = "t.exr: not a partial image of `arbor render` (it is tiled or deep, a partial is flat scan lines)";
        assert_eq!(e.to_string(), msg);
    }
}
