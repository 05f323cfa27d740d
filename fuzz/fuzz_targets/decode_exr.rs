//! OpenEXR: `arbor::image_io::decode` on any bytes as `fuzz.exr`, within the fuzzing budget (common.rs), into
//! colours and 8-bit RGB: an error or an image of the size its texels say, never a panic or an abort.
//! Also `arbor::farm::decode_partial` (the partial EXRs `arbor merge` reads): an error or a partial whose
//! window lies inside its frame, with one sum per pixel and a sample range inside `0..spp`.

#![no_main]

mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    common::decode_image(data, "fuzz.exr");
    let path = std::path::Path::new("fuzz.exr");
    if let Ok(p) = arbor::farm::decode_partial(data, path, &common::IMAGE_LIMITS) {
        let s = &p.sums;
        let (x0, y0, x1, y1) = s.window;
        assert!(
            x0 <= x1 && y0 <= y1 && x1 <= s.frame.0 && y1 <= s.frame.1,
            "window {:?} in frame {:?}",
            s.window,
            s.frame
        );
        assert_eq!(s.sums.len() as u64, (x1 - x0) as u64 * (y1 - y0) as u64, "sums of window {:?}", s.window);
        assert!(s.samples.0 < s.samples.1 && s.samples.1 <= s.spp, "samples {:?} of {}", s.samples, s.spp);
    }
});
