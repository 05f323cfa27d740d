//! METU XML scenes: `arbor::scene::parse_desc` on any UTF-8 text as `fuzz.xml`, then the geometry build
//! when every mesh is inline.

#![no_main]

mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| common::parse_and_build_scene(data, "fuzz.xml"));
