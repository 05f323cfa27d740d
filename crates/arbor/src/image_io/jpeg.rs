//! Whether JPEG data is whole: the image crate's decoder (zune-jpeg, not in strict mode) fills the rows
//! after a cut with grey and succeeds, so a file cut inside its compressed data would be read as an image.
//!
//! The check walks the file's structure (ITU T.81, annex B): marker segments carry their length and
//! are skipped whole; after a start-of-scan segment comes entropy-coded data, in which a 0xFF byte is
//! followed by 0x00 (a stuffed byte) or a restart marker, so the first other marker ends the scan.
//! The data is whole when the walk reaches the end-of-image marker. Stray bytes between segments are
//! skipped, as lenient decoders do. Cost: one pass over the bytes, no decoding.

/// End of image.
const EOI: u8 = 0xD9;
/// Start of scan: entropy-coded data follows its header.
const SOS: u8 = 0xDA;

/// True when the JPEG data `b` reaches its end-of-image marker; false when it ends first.
pub(super) fn is_whole(b: &[u8]) -> bool {
    // After the start-of-image marker.
    let mut i = 2;
    loop {
        // The next marker: 0xFF (repeated as fill) and a code.
        while b.get(i).is_some_and(|&x| x != 0xFF) {
            i += 1;
        }
        while b.get(i + 1) == Some(&0xFF) {
            i += 1;
        }
        let Some(&code) = b.get(i + 1) else { return false };
        i += 2;
        match code {
            EOI => return true,
            // Markers without a segment: restarts, TEM, and a stuffed zero met out of place.
            0x00 | 0x01 | 0xD0..=0xD7 => continue,
            _ => {}
        }
        let (Some(&hi), Some(&lo)) = (b.get(i), b.get(i + 1)) else { return false };
        // The length counts its own two bytes.
        i += usize::from(u16::from_be_bytes([hi, lo]));
        if i > b.len() {
            return false;
        }
        if code == SOS {
            i = scan_end(b, i);
        }
    }
}

/// Where the entropy-coded data starting at `i` ends: at the first marker that is neither a stuffed
/// byte nor a restart, or at the end of `b`.
fn scan_end(b: &[u8], mut i: usize) -> usize {
    while i + 1 < b.len() {
        if b[i] == 0xFF && !matches!(b[i + 1], 0x00 | 0xD0..=0xD7 | 0xFF) {
            return i;
        }
        i += 1;
    }
    b.len()
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::codecs::jpeg::JpegEncoder;
    use image::{ExtendedColorType, ImageEncoder};

    /// A 24x16 JPEG of a gradient (several blocks, so the scan is long).
    fn jpeg() -> Vec<u8> {
        let (w, h) = (24u32, 16u32);
        let px: Vec<u8> = (0..w * h).flat_map(|i| [(i * 7) as u8, (i * 3) as u8, (255 - i % 256) as u8]).collect();
        let mut out = Vec::new();
        JpegEncoder::new_with_quality(&mut out, 90).write_image(&px, w, h, ExtendedColorType::Rgb8).unwrap();
        out
    }

    #[test]
    fn jpeg_whole_file_is_whole_and_every_cut_is_not() {
        let b = jpeg();
        assert!(is_whole(&b));
        for n in 0..b.len() {
            assert!(!is_whole(&b[..n]), "cut at {n} of {}", b.len());
        }
    }

    #[test]
    fn jpeg_bytes_after_the_end_marker_and_restarts_in_the_scan_are_accepted() {
        let mut b = jpeg();
        b.extend_from_slice(b"trailing bytes");
        assert!(is_whole(&b));
        // A restart marker and a stuffed 0xFF inside the scan do not end it.
        let sos = b.windows(2).position(|w| w == [0xFF, SOS]).unwrap();
        let data = sos + 2 + usize::from(u16::from_be_bytes([b[sos + 2], b[sos + 3]]));
        let mut r = b[..data].to_vec();
        r.extend_from_slice(&[0x12, 0xFF, 0x00, 0x34, 0xFF, 0xD3, 0x56, 0xFF, EOI]);
        assert!(is_whole(&r));
        assert!(!is_whole(&r[..r.len() - 3]), "a scan ending in a restart marker");
    }

    #[test]
    fn jpeg_end_marker_inside_a_segment_does_not_count() {
        // An APP1 segment (where an EXIF thumbnail with its own end marker lives) cut short.
        let mut b = vec![0xFF, 0xD8, 0xFF, 0xE1, 0x00, 0x10, 0xFF, EOI];
        assert!(!is_whole(&b));
        b.resize(2 + 2 + 16, 0);
        b.extend_from_slice(&[0xFF, EOI]);
        assert!(is_whole(&b));
    }
}
