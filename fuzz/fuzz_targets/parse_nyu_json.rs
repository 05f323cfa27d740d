//! NYU `scene.json` scenes: `arbor::scene::parse_desc` on any UTF-8 text as `scene.json`, then the
//! geometry build when every mesh is inline. Seeded with NYU scenes (top-level `Camera`/`Objects`).

#![no_main]

mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| common::parse_and_build_scene(data, "scene.json"));
