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

/// Reserves and releases the memory of [`need`], or says that there is not enough.
pub fn reserve_for(width: u32, height: u32, window: (u32, u32, u32, u32), partial: bool) -> Result<(), Failure> {
    let bytes = need(width, height, window, partial);
    let mut probe: Vec<u8> = Vec::new();
    if usize::try_from(bytes).ok().and_then(|n| probe.try_reserve_exact(n).ok()).is_none() {
        let (w, h) = (window.2 - window.0, window.3 - window.1);
        let gib = bytes as f64 / (1u64 << 30) as f64;
        return Err(Failure::OutOfMemory(format!("not enough memory for a {w}x{h} image ({gib:.1} GiB)")));
    }
    Ok(())
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
    fn memory_reservation_beyond_any_machine_fails_with_the_size() {
        let Err(Failure::OutOfMemory(msg)) = reserve_for(4_000_000, 4_000_000, (0, 0, 4_000_000, 4_000_000), false)
        else {
            panic!("16 terapixels reserved");
        };
        assert_eq!(msg, "not enough memory for a 4000000x4000000 image (1490116.1 GiB)");
        assert!(reserve_for(64, 64, (0, 0, 64, 64), false).is_ok());
    }
}
