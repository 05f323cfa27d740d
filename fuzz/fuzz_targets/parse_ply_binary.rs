//! PLY in binary (both byte orders): `arbor::mesh_io::parse_ply` on any bytes, seeded with binary files (fuzz/seeds/parse_ply_binary), so mutations start from binary bodies.

#![no_main]

mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(mesh) = arbor::mesh_io::parse_ply(data, std::path::Path::new("fuzz.ply")) {
        common::check_mesh(&mesh, "ply_binary");
    }
});
