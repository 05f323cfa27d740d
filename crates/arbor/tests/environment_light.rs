//! Environment lights (`SphericalDirectionalLight`) against answers known in closed form: a white
//! diffuse sphere under a uniform sky of radiance `L` reflects `π L` (the course's diffuse term has no
//! `1/π`), and camera rays that miss see `L` itself.

use std::path::Path;

use arbor::accel::AccelConfig;
use arbor::film::Film;
use arbor::image_io::write_image;
use arbor::math::Color;
use arbor::render::{render, RenderOptions};
use arbor::scene::{load_desc, Scene};

/// A white diffuse sphere of radius 2 six units in front of a camera at the origin, lit only by the
/// lat-long map `sky.exr`.
fn scene_lit_by(dir: &Path, sky: Film) -> Scene {
    write_image(&dir.join("sky.exr"), &sky).unwrap();
    let xml = r#"<Scene>
    <Cameras><Camera id="1" type="lookAt">
        <Position>0 0 0</Position><GazePoint>0 0 -1</GazePoint><Up>0 1 0</Up><FovY>90</FovY>
        <NearDistance>1</NearDistance><ImageResolution>40 40</ImageResolution>
        <ImageName>out.exr</ImageName><NumSamples>64</NumSamples>
    </Camera></Cameras>
    <VertexData>0 0 -6</VertexData>
    <Materials><Material id="1">
        <AmbientReflectance>0 0 0</AmbientReflectance><DiffuseReflectance>1 1 1</DiffuseReflectance>
        <SpecularReflectance>0 0 0</SpecularReflectance><PhongExponent>1</PhongExponent>
    </Material></Materials>
    <Textures><Images><Image id="1">sky.exr</Image></Images></Textures>
    <Lights><SphericalDirectionalLight id="1"><ImageId>1</ImageId></SphericalDirectionalLight></Lights>
    <Objects><Sphere id="1"><Center>1</Center><Radius>2</Radius><Material>1</Material></Sphere></Objects>
</Scene>"#;
    std::fs::write(dir.join("env.xml"), xml).unwrap();
    let desc = load_desc(&dir.join("env.xml")).unwrap();
    Scene::build(desc, &AccelConfig::default(), None).unwrap()
}

/// Mean of the pixels in `[x0, x1) x [y0, y1)`.
fn mean(film: &Film, (x0, x1): (u32, u32), (y0, y1): (u32, u32)) -> Color {
    let mut sum = Color::ZERO;
    for y in y0..y1 {
        for x in x0..x1 {
            sum += film.get(x, y);
        }
    }
    sum / ((x1 - x0) * (y1 - y0)) as f32
}

#[test]
fn environment_light_uniform_sky_on_a_white_diffuse_sphere_gives_pi_l() {
    let tmp = tempfile::tempdir().unwrap();
    let l = 0.1;
    let scene = scene_lit_by(tmp.path(), Film { width: 64, height: 32, pixels: vec![Color::splat(l); 64 * 32] });
    // Half the directions drawn from the whole sphere are below the surface: the estimate of one
    // sample is about as large as its mean. 64 pixels of 400 samples bring that to about 0.6%.
    let opts = RenderOptions { spp: Some(400), ..Default::default() };
    let (film, _) = render(&scene, 0, &opts, &|_, _| {}).unwrap();
    // The corner pixels miss the sphere: they see the sky.
    assert!((film.get(0, 0) - Color::splat(l)).abs().max_element() < 1e-6, "{}", film.get(0, 0));
    let centre = mean(&film, (16, 24), (16, 24));
    let want = std::f32::consts::PI * l;
    assert!((centre - Color::splat(want)).abs().max_element() < 0.02 * want, "{centre} vs {want}");
}

#[test]
fn environment_light_a_sky_lit_from_above_lights_the_top_of_the_sphere() {
    let tmp = tempfile::tempdir().unwrap();
    // Rows 0..32 of 64 are the upper hemisphere (v = acos(y) / π).
    let pixels = (0..128 * 64).map(|i| if i < 128 * 32 { Color::ONE } else { Color::ZERO }).collect();
    let scene = scene_lit_by(tmp.path(), Film { width: 128, height: 64, pixels });
    let (film, _) = render(&scene, 0, &RenderOptions::default(), &|_, _| {}).unwrap();
    let (top, bottom) = (mean(&film, (18, 22), (14, 16)), mean(&film, (18, 22), (24, 26)));
    assert!(top.x > 3.0 * bottom.x, "top {top}, bottom {bottom}");
    assert_eq!(film.get(20, 39), Color::ZERO, "below the horizon the sky is black");
}
