//! Mesh readers end to end: `load_mesh` on small fixtures and on every real mesh in the shared folders.

mod common;

use std::path::{Path, PathBuf};

use arbor::geometry::TriangleMesh;
use arbor::math::Vec3;
use arbor::mesh_io::{load_mesh, parse_obj, parse_off, parse_ply};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/meshes").join(name)
}

/// What every loaded mesh must satisfy, whatever the format.
fn assert_valid(m: &TriangleMesh, what: &Path) {
    let n = m.positions.len() as u32;
    assert!(m.indices.iter().flatten().all(|&i| i < n), "{}", what.display());
    assert!(m.positions.iter().all(|p| p.is_finite()), "{}", what.display());
    for attr in [m.normals.as_ref().map(Vec::len), m.uvs.as_ref().map(Vec::len)] {
        assert!(attr.is_none_or(|l| l == m.positions.len()), "{}", what.display());
    }
}

#[test]
fn load_mesh_reads_each_format() {
    let obj = load_mesh(&fixture("tetra.obj")).unwrap();
    let off = load_mesh(&fixture("tetra.off")).unwrap();
    assert_eq!(obj.len(), 4);
    assert_eq!(off.len(), 4);
    // Only the first face names uvs and normals, so the OBJ keeps neither and its vertices as they are.
    assert!(obj.uvs.is_none() && obj.normals.is_none());
    assert_eq!(obj.positions, off.positions);
    assert_eq!(obj.indices[3], [0, 3, 2]);
    assert_eq!(obj.indices, off.indices);

    let ply = load_mesh(&fixture("square_pyramid.ply")).unwrap();
    assert_eq!(ply.len(), 6);
    assert_eq!(ply.normals.as_ref().unwrap()[4], Vec3::Z);
    for m in [&obj, &off, &ply] {
        assert_valid(m, Path::new("fixture"));
    }
}

#[test]
fn load_mesh_extension_is_case_insensitive() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("TETRA.Off");
    std::fs::copy(fixture("tetra.off"), &path).unwrap();
    assert_eq!(load_mesh(&path).unwrap().len(), 4);
}

#[test]
fn load_mesh_missing_file_is_io_error() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("absent.ply");
    let err = load_mesh(&path).unwrap_err();
    assert!(err.is_io());
    let want = format!("{}: No such file or directory (os error 2)", path.display());
    assert_eq!(err.to_string(), want);
}

#[test]
fn load_mesh_unknown_extension_is_input_error() {
    let err = load_mesh(Path::new("models/teapot.stl")).unwrap_err();
    assert!(!err.is_io());
    assert_eq!(err.to_string(), "models/teapot.stl: unknown mesh file extension `.stl` (supported: .ply, .obj, .off)");
}

/// A binary PLY built here, in both byte orders, written to disk and loaded back.
#[test]
fn load_mesh_binary_ply_both_byte_orders() {
    let dir = tempfile::tempdir().unwrap();
    let mut meshes = Vec::new();
    for (format, le) in [("binary_little_endian", true), ("binary_big_endian", false)] {
        let mut bytes = format!(
            "ply\nformat {format} 1.0\nelement vertex 4\nproperty float z\nproperty float y\n\
property float x\nproperty float u\nproperty float v\nelement face 1\n\
property list uchar uint vertex_indices\nend_header\n"
        )
        .into_bytes();
        let f = |v: f32| if le { v.to_le_bytes() } else { v.to_be_bytes() };
        for (x, y) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
            for v in [0.0, y, x, x, y] {
                bytes.extend_from_slice(&f(v));
            }
        }
        bytes.push(4);
        for i in 0u32..4 {
            bytes.extend_from_slice(&if le { i.to_le_bytes() } else { i.to_be_bytes() });
        }
        let path = dir.path().join(format!("{format}.ply"));
        std::fs::write(&path, &bytes).unwrap();
        meshes.push(load_mesh(&path).unwrap());
    }
    assert_eq!(meshes[0], meshes[1]);
    assert_eq!(meshes[0].indices, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(meshes[0].positions[2], Vec3::new(1.0, 1.0, 0.0));
    assert_eq!(meshes[0].uvs.as_ref().unwrap()[3].to_array(), [0.0, 1.0]);
}

#[test]
fn parse_errors_name_file_and_place() {
    let p = Path::new("in/m");
    let cases: [(&str, String); 4] = [
        ("obj", parse_obj(b"v 0 0 0\nv 1 0 0\nf 1 2 3\n", p).unwrap_err().to_string()),
        ("off", parse_off(b"OFF\n1 1 0\n0 0 0\n3 0 0 1\n", p).unwrap_err().to_string()),
        (
            "ply",
            parse_ply(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 1e99\n", p)
                .unwrap_err()
                .to_string(),
        ),
        (
            "ply binary",
            parse_ply(b"ply\nformat binary_little_endian 1.0\nelement vertex 99\nproperty double x\nproperty double y\nproperty double z\nend_header\n\0\0", p)
                .unwrap_err()
                .to_string(),
        ),
    ];
    let want = [
        "in/m:3:7: vertex index 3 out of range (2 defined so far)",
        "in/m:4:7: face 0: vertex index 1 out of range (the file has 1 vertices)",
        "in/m:8: vertex 0: non-finite z (inf)",
        "in/m:3: element `vertex` claims 99 entries (at least 2376 bytes) but only 2 bytes are left for it",
    ];
    for ((what, got), want) in cases.iter().zip(want) {
        assert_eq!(got, want, "{what}");
    }
}

/// Seeds for the mutation test: one valid file per reader and layout.
fn seeds() -> Vec<(&'static str, Vec<u8>)> {
    let mut out: Vec<(&str, Vec<u8>)> = ["tetra.obj", "tetra.off", "square_pyramid.ply"]
        .iter()
        .map(|n| (*n, std::fs::read(fixture(n)).unwrap()))
        .collect();
    let mut bin = b"ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\n\
property float y\nproperty float z\nproperty list uchar short w\nelement face 2\n\
property list uchar int vertex_indices\nelement tristrips 1\nproperty list uint int vertex_indices\n\
end_header\n"
        .to_vec();
    for v in 0..3u8 {
        bin.extend_from_slice(&[0, 0, 0, v, 0x3f, 0x80, 0, 0, 0, 0, 0, 0, 1, 0, 7]);
    }
    for _ in 0..2 {
        bin.extend_from_slice(&[3, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 2]);
    }
    bin.extend_from_slice(&[0, 0, 0, 3, 0, 0, 0, 2, 0, 0, 0, 1, 0, 0, 0, 0]);
    out.push(("mutated.ply", bin));
    out
}

#[test]
fn mutation_seeds_are_valid() {
    for (name, bytes) in seeds() {
        let m = match &name[name.len() - 3..] {
            "obj" => parse_obj(&bytes, Path::new(name)),
            "off" => parse_off(&bytes, Path::new(name)),
            _ => parse_ply(&bytes, Path::new(name)),
        };
        assert!(!m.unwrap_or_else(|e| panic!("{e}")).is_empty(), "{name}");
    }
}

proptest::proptest! {
    /// No input makes a reader panic: random byte changes and truncations of valid files either parse
    /// into a valid mesh or give an error.
    #[test]
    fn readers_never_panic_on_mutated_input(
        seed in 0usize..4,
        edits in proptest::collection::vec((0usize..4096, proptest::num::u8::ANY), 0..6),
        cut in 0usize..4096,
    ) {
        let (_, mut bytes) = seeds().swap_remove(seed);
        for (pos, b) in edits {
            let n = bytes.len();
            bytes[pos % n] = b;
        }
        bytes.truncate(bytes.len() - cut % (bytes.len() / 4 + 1));
        let p = Path::new("m");
        for m in [parse_obj(&bytes, p), parse_off(&bytes, p), parse_ply(&bytes, p)].into_iter().flatten() {
            assert_valid(&m, p);
        }
    }
}

/// Every .ply, .obj and .off file under `dir`, sorted.
fn mesh_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
            if path.is_dir() {
                stack.push(path);
            } else if matches!(ext.as_deref(), Some("ply" | "obj" | "off")) {
                out.push(path);
            }
        }
    }
    out.sort();
    out
}

#[test]
fn real_meshes_load_with_known_triangle_counts() {
    let Some(dir) = common::meshes_dir() else {
        return;
    };
    let known = [
        ("stanford-bunny.obj", 69_451),
        ("horse.ply", 96_966),
        ("nefertiti.obj", 99_938),
        ("ogre.obj", 124_008),
        ("igea.ply", 268_686),
    ];
    let files = mesh_files(&dir);
    assert!(files.len() >= known.len());
    for path in &files {
        let m = load_mesh(path).unwrap_or_else(|e| panic!("{e}"));
        assert_valid(&m, path);
        let name = path.file_name().unwrap().to_string_lossy();
        if let Some(&(_, n)) = known.iter().find(|(k, _)| *k == name) {
            assert_eq!(m.len(), n, "{name}");
        }
        if name == "horse.ply" {
            assert!(m.normals.is_some());
        }
    }
}

#[test]
fn real_scene_meshes_load_with_known_triangle_counts() {
    let Some(dir) = common::scenes_dir() else {
        return;
    };
    // Counts from the files' own headers and face lines (quads count twice).
    let known = [
        ("nyu-cg-assignment4/Assignment_4/data/bunny.off", 996),
        ("nyu-cg-assignment4/Assignment_4/data/cube.off", 12),
        ("nyu-cg-assignment4/Assignment_4/data/dodeca.off", 36),
        ("ceng795-2019/inputs/hw2/ply/cube.ply", 12),
        ("ceng795-2019/inputs/hw2/ply/tap_tap.ply", 10_484),
        ("ceng795-2019/inputs/hw2/ply/tap_water_200.ply", 39_660 + 2 * 80),
        ("ceng795-2019/inputs/hw5/ply/plane.ply", 2),
        ("ceng795-2024-hw1/hw1/inputs/akif_uslu/ton_Roosendaal_smooth_ply/mesh_2.ply", 62_160),
    ];
    let mut ton_total = 0;
    let files = mesh_files(&dir);
    for path in &files {
        let m = load_mesh(path).unwrap_or_else(|e| panic!("{e}"));
        assert_valid(&m, path);
        assert!(!m.is_empty(), "{}", path.display());
        let rel = path.strip_prefix(&dir).unwrap();
        if let Some(&(_, n)) = known.iter().find(|(k, _)| Path::new(k) == rel) {
            assert_eq!(m.len(), n, "{}", rel.display());
        }
        let rel = rel.to_string_lossy();
        if rel.starts_with("ceng795-2024-hw1/") && rel.contains("ton_Roosendaal_smooth_ply/") {
            ton_total += m.len();
        }
    }
    if files.iter().any(|p| p.to_string_lossy().contains("ceng795-2024-hw1")) {
        assert_eq!(ton_total, 78_620);
    }
}
