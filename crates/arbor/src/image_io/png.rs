//! A PNG's palettes checked before it is decoded: the png crate (0.18.1) takes a `PLTE` chunk whose
//! length is not a multiple of 3, within its 3 to 768 bytes, and then panics when it expands the palette
//! (image-rs/image-png#694, fixed there after 0.18.1; found here by the `decode_png` fuzz target). The
//! PNG specification (11.2.3) requires whole RGB entries, so such a file is bad input.
//!
//! The check walks the chunks (length, type, data, CRC) to the end of the data: a few bytes read per
//! chunk, no decoding. A chunk length past the end ends the walk; the decoder reports that itself.

/// The length of the first `PLTE` chunk of the PNG data `b` that is not a whole number of RGB entries.
pub(super) fn broken_palette(b: &[u8]) -> Option<u32> {
    // After the 8-byte signature.
    let mut i: usize = 8;
    while let Some(head) = b.get(i..i.saturating_add(8)) {
        let len = u32::from_be_bytes([head[0], head[1], head[2], head[3]]);
        if &head[4..8] == b"PLTE" && len % 3 != 0 {
            return Some(len);
        }
        i = i.saturating_add(12).saturating_add(len as usize);
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A PNG's chunks (CRCs left zero: the walk does not read them).
    fn png(chunks: &[(&[u8; 4], usize)]) -> Vec<u8> {
        let mut b = b"\x89PNG\r\n\x1a\n".to_vec();
        for (kind, len) in chunks {
            b.extend_from_slice(&(*len as u32).to_be_bytes());
            b.extend_from_slice(*kind);
            b.resize(b.len() + len + 4, 0);
        }
        b
    }

    #[test]
    fn png_palette_of_part_entries_is_found_and_whole_ones_are_not() {
        assert_eq!(broken_palette(&png(&[(b"IHDR", 13), (b"PLTE", 12), (b"IDAT", 9), (b"IEND", 0)])), None);
        assert_eq!(broken_palette(&png(&[(b"IHDR", 13), (b"PLTE", 13), (b"IDAT", 9)])), Some(13));
        assert_eq!(broken_palette(&png(&[(b"IHDR", 13), (b"tEXt", 5), (b"PLTE", 4)])), Some(4));
        // Cut inside a chunk, or a length past the end: the walk stops.
        let cut = png(&[(b"IHDR", 13), (b"PLTE", 13)]);
        assert_eq!(broken_palette(&cut[..30]), None);
        let mut huge = png(&[(b"IHDR", 13)]);
        huge.extend_from_slice(&u32::MAX.to_be_bytes());
        huge.extend_from_slice(b"IDAT");
        assert_eq!(broken_palette(&huge), None);
        assert_eq!(broken_palette(b""), None);
    }
}
