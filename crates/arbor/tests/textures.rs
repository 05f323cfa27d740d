//! Textures stay on their objects: an image-textured, bump-mapped quad renders the same as a transformed
//! mesh, as a mesh instance and with its vertices moved by hand; a textured sphere moved by a translation
//! renders as one whose centre was moved; and a moving object's texture, seen by a ray at time t, is the
//! texture of the object frozen where it is at t.

use std::path::Path;

use arbor::accel::AccelConfig;
use arbor::camera::RayCone;
use arbor::film::Film;
use arbor::math::{Ray, Vec3};
use arbor::render::{render, RenderOptions};
use arbor::scene::{parse_desc, Scene};

/// A 4x4 image of distinct colours, written as `tex.png` in `dir`.
fn write_texture(dir: &Path) {
    let bytes: Vec<u8> = (0..16u32).flat_map(|i| [i * 16, 255 - i * 13, (i * 57) % 251].map(|b| b as u8)).collect();
    image::RgbImage::from_raw(4, 4, bytes).unwrap().save(dir.join("tex.png")).unwrap();
}

/// A scene around `objects`, with `vertices`, `texcoords` and `transforms`: a camera looking down -z
/// from z = 6, a light, one material, an image map (replace_kd, bilinear) and a bump map of the same
/// image.
fn scene(vertices: &str, texcoords: &str, transforms: &str, objects: &str) -> String {
    format!(
        r#"<Scene><BackgroundColor>5 5 5</BackgroundColor>
        <Cameras><Camera id="1"><Position>0 0 6</Position><Gaze>0 0 -1</Gaze><Up>0 1 0</Up>
        <NearPlane>-1 1 -1 1</NearPlane><NearDistance>2</NearDistance><ImageResolution>40 40</ImageResolution>
        <ImageName>a.png</ImageName></Camera></Cameras>
        <Lights><AmbientLight>20 20 20</AmbientLight><PointLight id="1"><Position>1 2 5</Position>
        <Intensity>600 600 600</Intensity></PointLight></Lights>
        <Materials><Material id="1"><AmbientReflectance>0.2 0.2 0.2</AmbientReflectance>
        <DiffuseReflectance>1 1 1</DiffuseReflectance><SpecularReflectance>0.5 0.5 0.5</SpecularReflectance>
        <PhongExponent>20</PhongExponent></Material></Materials>
        <Textures><Images><Image id="1">tex.png</Image></Images>
        <TextureMap id="1" type="image"><ImageId>1</ImageId><DecalMode>replace_kd</DecalMode>
        <Interpolation>bilinear</Interpolation></TextureMap>
        <TextureMap id="2" type="image"><ImageId>1</ImageId><DecalMode>bump_normal</DecalMode>
        <BumpFactor>0.02</BumpFactor></TextureMap>
        <TextureMap id="3" type="checkerboard"><DecalMode>replace_kd</DecalMode><Scale>3</Scale>
        <Offset>0.01</Offset><BlackColor>0 0 0</BlackColor><WhiteColor>1 1 1</WhiteColor></TextureMap>
        </Textures>
        <Transformations>{transforms}</Transformations>
        <VertexData>{vertices}</VertexData><TexCoordData>{texcoords}</TexCoordData>
        <Objects>{objects}</Objects></Scene>"#
    )
}

fn load(dir: &Path, text: &str) -> Scene {
    let path = dir.join("s.xml");
    let desc = parse_desc(text, &path).unwrap_or_else(|e| panic!("{e}"));
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    Scene::build(desc, &AccelConfig::default(), None).unwrap()
}

fn film(dir: &Path, text: &str) -> Film {
    render(&load(dir, text), 0, &RenderOptions::default(), &|_, _| {}).unwrap().0
}

/// Pixels whose channels differ by more than `tol` (relative to 1 or the value).
fn differing(a: &Film, b: &Film, tol: f32) -> usize {
    let scale = |c: Vec3| c.max_element().max(1.0);
    a.pixels.iter().zip(&b.pixels).filter(|(x, y)| (**x - **y).abs().max_element() > tol * scale(**y)).count()
}

/// Covered pixels (not the background), so that a test cannot pass on an empty image.
fn covered(f: &Film) -> usize {
    f.pixels.iter().filter(|c| (**c - Vec3::splat(5.0)).abs().max_element() > 1e-3).count()
}

const QUAD: &str = "-1 -1 0  1 -1 0  1 1 0  -1 1 0";
const UV: &str = "0 0  1 0  1 1  0 1";
const FACES: &str = "1 2 3  1 3 4";

#[test]
fn textures_follow_a_rigid_transform_and_an_instance() {
    let tmp = tempfile::tempdir().unwrap();
    write_texture(tmp.path());
    // Rotate 30 degrees about (1, 1, 0.5), then move by (0.2, -0.1, 0.5).
    let transforms = r#"<Rotation id="1">30 1 1 0.5</Rotation><Translation id="1">0.2 -0.1 0.5</Translation>"#;
    let mesh = |t: &str| {
        format!(r#"<Mesh id="1"><Material>1</Material><Textures>1 2</Textures>{t}<Faces>{FACES}</Faces></Mesh>"#)
    };
    let transformed = film(tmp.path(), &scene(QUAD, UV, transforms, &mesh("<Transformations>r1 t1</Transformations>")));
    // The same quad with its vertices moved by hand.
    let axis = Vec3::new(1.0, 1.0, 0.5).normalize();
    let rot = arbor::math::Mat4::from_axis_angle(axis, 30f32.to_radians());
    let moved: Vec<String> = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]
        .iter()
        .map(|[x, y]| rot.transform_point3(Vec3::new(*x, *y, 0.0)) + Vec3::new(0.2, -0.1, 0.5))
        .map(|p| format!("{} {} {}", p.x, p.y, p.z))
        .collect();
    let by_hand = film(tmp.path(), &scene(&moved.join("  "), UV, transforms, &mesh("")));
    // An instance of a copy behind the camera, placed by the same transform.
    let instance = format!(
        r#"{}<MeshInstance id="2" baseMeshId="1" resetTransform="true"><Material>1</Material>
        <Textures>1 2</Textures><Transformations>r1 t1</Transformations></MeshInstance>"#,
        mesh(r#"<Transformations>t2</Transformations>"#)
    );
    let far = format!(r#"{transforms}<Translation id="2">0 0 100</Translation>"#);
    let instanced = film(tmp.path(), &scene(QUAD, UV, &far, &instance));
    assert!(covered(&transformed) > 500, "the quad fills part of the image");
    assert_eq!(differing(&transformed, &by_hand, 1e-3), 0, "transformed mesh against vertices moved by hand");
    assert_eq!(differing(&transformed, &instanced, 1e-3), 0, "transformed mesh against its instance");
}

#[test]
fn textures_of_a_sphere_move_with_it() {
    let tmp = tempfile::tempdir().unwrap();
    write_texture(tmp.path());
    let sphere = |centre: u32, t: &str| {
        format!(
            r#"<Sphere id="1"><Material>1</Material><Textures>1 2</Textures><Center>{centre}</Center>
            <Radius>0.8</Radius>{t}</Sphere>"#
        )
    };
    let vertices = "0 0 0  0.3 -0.2 0.4";
    let translated = scene(
        vertices,
        "",
        r#"<Translation id="1">0.3 -0.2 0.4</Translation>"#,
        &sphere(1, "<Transformations>t1</Transformations>"),
    );
    let moved = scene(vertices, "", "", &sphere(2, ""));
    let (a, b) = (film(tmp.path(), &translated), film(tmp.path(), &moved));
    assert!(covered(&a) > 500);
    assert_eq!(differing(&a, &b, 1e-3), 0);
}

#[test]
fn textures_of_a_moving_object_are_those_of_the_object_frozen_at_the_rays_time() {
    let tmp = tempfile::tempdir().unwrap();
    write_texture(tmp.path());
    let motion = Vec3::new(0.6, 0.2, -0.3);
    // A checkerboard sphere and a checkerboard, bump-mapped quad, moving.
    let objects = |blur: &str, centre: u32| {
        format!(
            r#"<Sphere id="1"><Material>1</Material><Textures>3 2</Textures><Center>{centre}</Center>
            <Radius>0.5</Radius>{blur}</Sphere>
            <Mesh id="2"><Material>1</Material><Textures>3 2</Textures>{blur}<Faces>{FACES}</Faces></Mesh>"#
        )
    };
    let quad_at = |shift: Vec3| -> String {
        QUAD.split("  ")
            .map(|v| {
                let c: Vec<f32> = v.split(' ').map(|x| x.parse().unwrap()).collect();
                let p = Vec3::new(c[0], c[1], c[2] - 1.5) + shift;
                format!("{} {} {}", p.x, p.y, p.z)
            })
            .collect::<Vec<_>>()
            .join("  ")
    };
    let blur = format!("<MotionBlur>{} {} {}</MotionBlur>", motion.x, motion.y, motion.z);
    let vertices = format!("{}  0 0 0.5", quad_at(Vec3::ZERO));
    let moving = load(tmp.path(), &scene(&vertices, UV, "", &objects(&blur, 5)));
    let cone = RayCone { width: 0.0, spread: 0.0 };
    let shade = |scene: &Scene, ray: &Ray| {
        let hit = scene.geometry.intersect(ray, f32::INFINITY)?;
        let mut s = scene.surface(ray, &hit);
        let t = scene.textured(ray, &hit, &mut s, cone).unwrap();
        Some((s.object, t.diffuse, s.ns))
    };
    let mut checked = [0; 2];
    for (k, time) in [0.0, 0.3, 0.75, 1.0].into_iter().enumerate() {
        let shift = motion * time;
        // The quad frozen where it is at `time` by a translation (its object space unchanged).
        let frozen_objects = objects("<Transformations>t1</Transformations>", 5);
        let translation = format!(r#"<Translation id="1">{} {} {}</Translation>"#, shift.x, shift.y, shift.z);
        let frozen = load(tmp.path(), &scene(&vertices, UV, &translation, &frozen_objects));
        for i in 0..400 {
            let (x, y) = ((i % 20) as f32 / 10.0 - 1.0, (i / 20) as f32 / 10.0 - 1.0 + 0.013 * k as f32);
            let dir = Vec3::new(x, y, -4.0).normalize();
            let ray = Ray::new(Vec3::new(0.0, 0.0, 6.0), dir).with_time(time);
            let Some((object, diffuse, ns)) = shade(&moving, &ray) else { continue };
            // The same surface point met at time 0 by the ray moved back: the texture moves with the
            // object, it does not slide over it during the shutter.
            let back = Ray::new(ray.origin - shift, dir);
            let (o0, d0, n0) = shade(&moving, &back).unwrap();
            assert_eq!(o0, object);
            assert!(diffuse.abs_diff_eq(d0, 1e-3), "time {time}, ray {i}: {diffuse} vs {d0} at time 0");
            assert!(ns.abs_diff_eq(n0, 1e-3), "time {time}, ray {i}: normal {ns} vs {n0} at time 0");
            if object == 1 {
                let (o2, d2, n2) = shade(&frozen, &Ray::new(ray.origin, dir)).unwrap();
                assert_eq!(o2, 1);
                assert!(diffuse.abs_diff_eq(d2, 1e-3), "time {time}, ray {i}: {diffuse} vs {d2} frozen");
                assert!(ns.abs_diff_eq(n2, 1e-3), "time {time}, ray {i}: normal {ns} vs {n2} frozen");
            }
            checked[usize::from(object == 1)] += 1;
        }
    }
    assert!(checked[0] > 100 && checked[1] > 100, "rays met both objects: {checked:?}");
}
