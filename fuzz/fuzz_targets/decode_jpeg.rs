//! JPEG: `arbor::image_io::decode` on any bytes as `fuzz.jpg`, within the fuzzing budget (common.rs), into
//! colours and 8-bit RGB: an error or an image of the size its texels say, never a panic or an abort.

#![no_main]

mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    common::decode_image(data, "fuzz.jpg");
});
