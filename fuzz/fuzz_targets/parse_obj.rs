//! `arbor::mesh_io::parse_obj` on any bytes: an error or a mesh that keeps the readers' promises, never a panic.

#![no_main]

mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(mesh) = arbor::mesh_io::parse_obj(data, std::path::Path::new("fuzz.obj")) {
        common::check_mesh(&mesh, "obj");
    }
});
