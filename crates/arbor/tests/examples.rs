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

/// Mean and variance of the red channel over the rows `rows` of a film.
fn row_stats(film: &arbor::film::Film, rows: std::ops::Range<u32>) -> (f64, f64) {
    let w = film.width as usize;
    let v: Vec<f64> =
        rows.flat_map(|y| (0..w).map(move |x| y as usize * w + x)).map(|i| film.pixels[i].x as f64).collect();
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    (mean, v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / v.len() as f64)
}

#[test]
fn examples_trilinear_checker_averages_towards_the_horizon_where_nearest_aliases() {
    use arbor::scene::desc::{Interpolation, TextureSource};
    let render_with = |filter: Interpolation| {
        let mut desc = load_desc(&examples().join("trilinear.xml")).unwrap();
        assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
        let TextureSource::Image { interpolation, .. } = &mut desc.textures[0].source else { panic!() };
        assert_eq!(*interpolation, Interpolation::Trilinear);
        *interpolation = filter;
        (desc.cameras[0].width, desc.cameras[0].height) = (128, 128);
        let scene = Scene::build(desc, &AccelConfig::default(), None).unwrap();
        render(&scene, 0, &RenderOptions::default(), &|_, _| {}).unwrap().0
    };
    let (tri, near) = (render_with(Interpolation::Trilinear), render_with(Interpolation::Nearest));
    // The horizon is near row 30. Rows 34..44 see the quad 15 to 50 units away, where one pixel's
    // footprint runs over 2 to 30 texels: one sample of nearest lands on black or white (a standard
    // deviation of 0.5), the mipmap averages them to the image's mean, 0.5.
    let (tm, tv) = row_stats(&tri, 34..44);
    let (nm, nv) = row_stats(&near, 34..44);
    assert!((tm - 0.5).abs() < 0.02 && tv < nv / 25.0, "trilinear {tm} ± {}, nearest {nm} ± {}", tv.sqrt(), nv.sqrt());
    assert!(nv > 0.2, "nearest {nm} ± {}", nv.sqrt());
    // Near the camera a pixel spans a tenth of a texel: the finest level, the checks' contrast stays
    // (a bilinear blend between them).
    let (_, close) = row_stats(&tri, 110..128);
    assert!(close.sqrt() > 0.15, "{}", close.sqrt());
}
