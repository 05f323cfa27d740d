//! Checks shared by the parser targets: what a reader promises about the data it returns, beyond not
//! panicking. A broken promise is a panic here, so libFuzzer records the input as a crash.

#![allow(dead_code)]

use std::path::Path;

use arbor::accel::AccelConfig;
use arbor::geometry::TriangleMesh;
use arbor::image_io::ImageLimits;
use arbor::math::Color;
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

/// The pixel budget of the image targets: the same checks as the default budget (2^26), with every
/// buffer at most a few tens of MB, well inside libFuzzer's 1 GiB.
pub const IMAGE_LIMITS: ImageLimits = ImageLimits { max_pixels: 1 << 20 };

/// Decodes `data` as the image file `name` (whose extension is the format when the bytes do not tell)
/// into colours and into 8-bit RGB through `arbor::image_io::decode`, within [`IMAGE_LIMITS`]: both
/// succeed or both fail, and an image has the size the budget allows and the texels its size says.
pub fn decode_image(data: &[u8], name: &str) {
    let path = Path::new(name);
    let colours = arbor::image_io::decode::<Color>(data, path, &IMAGE_LIMITS);
    let bytes = arbor::image_io::decode::<u8>(data, path, &IMAGE_LIMITS);
    match (colours, bytes) {
        (Ok((w, h, colours)), Ok((w8, h8, bytes))) => {
            assert_eq!((w, h), (w8, h8), "{name}: two sizes");
            let n = w as u64 * h as u64;
            assert!(
                n <= IMAGE_LIMITS.max_pixels,
                "{name}: {w}x{h} read within a budget of {}",
                IMAGE_LIMITS.max_pixels
            );
            assert_eq!(colours.len() as u64, n, "{name}: {} colours for {w}x{h}", colours.len());
            assert_eq!(bytes.len() as u64, 3 * n, "{name}: {} bytes for {w}x{h}", bytes.len());
        }
        (Err(_), Err(_)) => {}
        (a, b) => panic!("{name}: colours {:?} but 8-bit {:?}", a.map(|_| ()), b.map(|_| ())),
    }
}
