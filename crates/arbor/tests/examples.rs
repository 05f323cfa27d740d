//! The repository's own example scenes (`examples/`): each loads without warnings, builds and renders,
//! and each example mesh that carries normals winds its triangles counter-clockwise around them (a mesh
//! whose winding disagrees is shaded from its back side, i.e. black).

use std::path::PathBuf;

use arbor::accel::AccelConfig;
use arbor::mesh_io::load_mesh;
use arbor::render::{render, RenderOptions};
use arbor::scene::{load_desc, Scene};

fn examples() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples")
}

#[test]
fn examples_load_build_and_render() {
    let mut seen = 0;
    for entry in std::fs::read_dir(examples()).unwrap().flatten() {
        let path = entry.path();
        if !path.extension().is_some_and(|e| e == "xml" || e == "json") {
            continue;
        }
        let mut desc = load_desc(&path).unwrap_or_else(|e| panic!("{e}"));
        assert!(desc.warnings.is_empty(), "{}: {:?}", path.display(), desc.warnings);
        for cam in &mut desc.cameras {
            (cam.width, cam.height) = (cam.width / 8, cam.height / 8);
        }
        let scene = Scene::build(desc, &AccelConfig::default(), None).unwrap_or_else(|e| panic!("{e}"));
        let (film, _) = render(&scene, 0, &RenderOptions::default(), &|_, _| {}).unwrap();
        let lit = film.pixels.iter().filter(|c| c.max_element() > 0.1).count();
        assert!(lit * 4 > film.pixels.len(), "{}: mostly dark", path.display());
        seen += 1;
    }
    assert!(seen >= 2);
}

#[test]
fn examples_meshes_wind_counter_clockwise_around_their_normals() {
    for entry in std::fs::read_dir(examples().join("meshes")).unwrap().flatten() {
        let mesh = load_mesh(&entry.path()).unwrap_or_else(|e| panic!("{e}"));
        let Some(normals) = &mesh.normals else { continue };
        let against = (0..mesh.len())
            .filter(|&i| {
                let [a, b, c] = mesh.triangle(i);
                let n: arbor::math::Vec3 = mesh.indices[i].iter().map(|&v| normals[v as usize]).sum();
                (b - a).cross(c - a).dot(n) < 0.0
            })
            .count();
        assert_eq!(against, 0, "{}: {against} triangles wound against their normals", entry.path().display());
    }
}
