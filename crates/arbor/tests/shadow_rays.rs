//! Where a shadow ray stops (`integrator::offset::shadow_ray`): in the METU formats a surface at the
//! light's own distance, or up to `ShadowRayEpsilon` beyond it, blocks the light. A room whose light
//! sits in (or just under) its ceiling is dark below; a light clearly below the ceiling lights the
//! floor. One pixel looks straight down at the floor of a 2-high room, from halfway up.

use std::path::Path;

use arbor::accel::AccelConfig;
use arbor::render::{render, RenderOptions};
use arbor::scene::{parse_desc, Scene};

/// The room with `light` (a `<PointLight>` or `<AreaLight>` element, or nothing) and the floor pixel's
/// 8-bit value.
fn floor_pixel(light: &str) -> u8 {
    let text = format!(
        r#"<Scene>
    <ShadowRayEpsilon>1e-3</ShadowRayEpsilon>
    <Cameras>
        <Camera id="1">
            <Position>0 1 0</Position>
            <Gaze>0 -1 0</Gaze>
            <Up>0 0 -1</Up>
            <NearPlane>-0.01 0.01 -0.01 0.01</NearPlane>
            <NearDistance>0.5</NearDistance>
            <ImageResolution>1 1</ImageResolution>
            <ImageName>room.png</ImageName>
        </Camera>
    </Cameras>
    <Lights>
        <AmbientLight>10 10 10</AmbientLight>
        {light}
    </Lights>
    <Materials>
        <Material id="1">
            <AmbientReflectance>1 1 1</AmbientReflectance>
            <DiffuseReflectance>1 1 1</DiffuseReflectance>
            <SpecularReflectance>0 0 0</SpecularReflectance>
        </Material>
    </Materials>
    <VertexData>
        -5 0 -5   5 0 -5   5 0 5   -5 0 5
        -5 2 -5   5 2 -5   5 2 5   -5 2 5
    </VertexData>
    <Objects>
        <Mesh id="1">
            <Material>1</Material>
            <Faces>1 3 2  1 4 3</Faces>
        </Mesh>
        <Mesh id="2">
            <Material>1</Material>
            <Faces>5 6 7  5 7 8</Faces>
        </Mesh>
    </Objects>
</Scene>"#
    );
    let desc = parse_desc(&text, Path::new("room.xml")).unwrap_or_else(|e| panic!("{e}"));
    let scene = Scene::build(desc, &AccelConfig::default(), None).unwrap();
    let (film, _) = render(&scene, 0, &RenderOptions::default(), &|_, _| {}).unwrap();
    film.to_rgb8()[0]
}

fn point_light(y: f32) -> String {
    format!("<PointLight id=\"1\"><Position>0 {y} 0</Position><Intensity>400 400 400</Intensity></PointLight>")
}

fn area_light(y: f32) -> String {
    format!(
        "<AreaLight id=\"1\"><Position>0 {y} 0</Position><Normal>0 -1 0</Normal><Size>0.5</Size>\
         <Radiance>1600 1600 1600</Radiance></AreaLight>"
    )
}

#[test]
fn shadow_light_in_the_ceiling_leaves_the_floor_dark() {
    let ambient = floor_pixel("");
    assert_eq!(ambient, 10);
    for (kind, light) in [("point", point_light as fn(f32) -> String), ("area", area_light)] {
        // In the ceiling's plane, and a fraction of the shadow epsilon under it: both blocked.
        assert_eq!(floor_pixel(&light(2.0)), ambient, "{kind} light in the ceiling");
        assert_eq!(floor_pixel(&light(1.9995)), ambient, "{kind} light 0.5 epsilon under the ceiling");
    }
}

#[test]
fn shadow_light_under_the_ceiling_lights_the_floor() {
    // 10 epsilons under the ceiling: 10 + 400 / 1.99² = 111.
    assert_eq!(floor_pixel(&point_light(1.99)), 111);
    // The area light's square is small and faces the floor: about 10 + 1600 * 0.25 / 1.99² = 111.
    assert!(floor_pixel(&area_light(1.99)) > 100);
}
