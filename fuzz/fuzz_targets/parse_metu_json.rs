//! METU JSON scenes (the 2025 form): `arbor::scene::parse_desc` on any UTF-8 text as `fuzz.json`, then
//! the geometry build when every mesh is inline. The same entry point reads NYU scenes when the top-level
//! keys say so; this target's seeds are METU scenes, `parse_nyu_json`'s are NYU ones.

#![no_main]

mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| common::parse_and_build_scene(data, "fuzz.json"));
