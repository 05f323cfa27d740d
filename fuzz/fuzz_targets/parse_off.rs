//! `arbor::mesh_io::parse_off` on any bytes: an error or a mesh that keeps the readers' promises, never a panic.

#![no_main]

mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(mesh) = arbor::mesh_io::parse_off(data, std::path::Path::new("fuzz.off")) {
        common::check_mesh(&mesh, "off");
    }
});
