//! Checks shared by the parser targets: what a reader promises about the data it returns, beyond not
//! panicking. A broken promise is a panic here, so libFuzzer records the input as a crash.

#![allow(dead_code)]

use std::path::Path;

use arbor::accel::AccelConfig;
use arbor::geometry::TriangleMesh;
use arbor::scene::{build_geometry, MeshSource, SceneDesc, ShapeDesc};

/// What `arbor::mesh_io` promises of a mesh it returns: every index in range, every coordinate finite,
/// and per-vertex attributes (when present) one per position.
pub fn check_mesh(mesh: &TriangleMesh, what: &str) {
    let n = mesh.positions.len();
    for (i, tri) in mesh.indices.iter().enumerate() {
        for &v in tri {
            assert!((v as usize) < n, "{what}: triangle {i} has index {v} but there are {n} positions");
        }
    }
    for (i, p) in mesh.positions.iter().enumerate() {
        assert!(p.is_finite(), "{what}: position {i} is not finite: {p:?}");
    }
    if let Some(normals) = &mesh.normals {
        assert_eq!(normals.len(), n, "{what}: {} normals for {n} positions", normals.len());
    }
    if let Some(uvs) = &mesh.uvs {
        assert_eq!(uvs.len(), n, "{what}: {} uvs for {n} positions", uvs.len());
    }
}

/// Parses `data` as the scene file `name` (whose extension picks the reader). When it parses and every
/// mesh is inline (no file is ever read while fuzzing), also builds its geometry under the default
/// structure, so the scene builder sees what the readers let through.
pub fn parse_and_build_scene(data: &[u8], name: &str) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let path = Path::new(name);
    let Ok(desc) = arbor::scene::parse_desc(text, path) else {
        return;
    };
    check_desc(&desc);
    if desc.objects.iter().any(|o| matches!(&o.shape, ShapeDesc::Mesh { source: MeshSource::File(_), .. })) {
        return;
    }
    // Errors are fine (an instance of a missing base, say); panics are not.
    let _ = build_geometry(&desc, &AccelConfig::default());
}

/// Inline meshes index only their own vertices, and every object's material exists (the renderer
/// indexes `materials` with it unchecked).
fn check_desc(desc: &SceneDesc) {
    for o in &desc.objects {
        if let ShapeDesc::Mesh { source: MeshSource::Inline(m), .. } = &o.shape {
            let n = m.positions.len();
            for (i, tri) in m.indices.iter().enumerate() {
                for &v in tri {
                    assert!((v as usize) < n, "{}: triangle {i} has index {v} but there are {n} positions", o.name);
                }
            }
        }
        assert!(o.material < desc.materials.len(), "{}: material {} of {}", o.name, o.material, desc.materials.len());
    }
}
