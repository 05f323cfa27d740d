//! Renders with answers known in closed form (pbrt's integrator tests in spirit): every scene is built
//! in code, rendered at one pixel whose camera ray is exactly the gaze, and the pixel compared with the
//! formula to single-precision accuracy.

use std::sync::Arc;

use arbor::accel::AccelConfig;
use arbor::geometry::TriangleMesh;
use arbor::math::{Color, Transform, Vec3};
use arbor::render::{render, RenderOptions};
use arbor::scene::{
    CameraDesc, LightDesc, MaterialDesc, MaterialKind, MeshSource, ObjectDesc, Scene, SceneDesc, ShapeDesc, Window,
};
use arbor::Location;

fn material(ambient: f32, diffuse: f32, kind: MaterialKind) -> MaterialDesc {
    MaterialDesc {
        degamma: false,
        id: "m".into(),
        ambient: Color::splat(ambient),
        diffuse: Color::splat(diffuse),
        specular: Color::ZERO,
        phong_exponent: 1.0,
        brdf: None,
        roughness: 0.0,
        kind,
    }
}

/// A square of side 2s at depth z, facing +z (towards the camera at z > 0) or -z.
fn quad(z: f32, s: f32, facing_camera: bool) -> ShapeDesc {
    let positions = vec![Vec3::new(-s, -s, z), Vec3::new(s, -s, z), Vec3::new(s, s, z), Vec3::new(-s, s, z)];
    let indices = if facing_camera { vec![[0, 1, 2], [0, 2, 3]] } else { vec![[0, 2, 1], [0, 3, 2]] };
    let mesh = TriangleMesh { positions, indices, ..Default::default() };
    ShapeDesc::Mesh { source: MeshSource::Inline(Arc::new(mesh)), smooth: false }
}

fn object(shape: ShapeDesc, material: usize) -> ObjectDesc {
    ObjectDesc {
        name: "o".into(),
        material,
        shape,
        transform: Transform::IDENTITY,
        motion: Vec3::ZERO,
        textures: Vec::new(),
        emission: None,
        loc: Location::file("test"),
    }
}

/// A scene with a one-pixel camera at z = 10 looking down -z, ambient 100 and the given content.
fn scene(materials: Vec<MaterialDesc>, objects: Vec<ObjectDesc>, lights: Vec<LightDesc>, depth: u32) -> SceneDesc {
    let mut d = SceneDesc::new("analytic.xml");
    d.radiance_scale = 1.0;
    d.ambient = Color::splat(100.0);
    d.max_depth = depth;
    // Small enough that the offset of secondary rays is below the tolerance of the comparisons.
    d.shadow_epsilon = 1e-5;
    d.materials = materials;
    d.objects = objects;
    d.lights = lights;
    d.cameras.push(CameraDesc {
        id: "1".into(),
        position: Vec3::new(0.0, 0.0, 10.0),
        gaze: -Vec3::Z,
        up: Vec3::Y,
        window: Window { left: -0.1, right: 0.1, bottom: -0.1, top: 0.1 },
        near_distance: 1.0,
        orthographic: false,
        width: 1,
        height: 1,
        image_name: "x.exr".into(),
        name_loc: Location::file("test"),
        num_samples: 1,
        transform: Transform::IDENTITY,
        lens: None,
        tonemap: None,
        renderer: Default::default(),
        loc: Location::file("test"),
    });
    d
}

fn pixel(desc: SceneDesc) -> Color {
    let s = Scene::build(desc, &AccelConfig::default(), None).unwrap();
    let (film, _) = render(&s, 0, &RenderOptions::default(), &|_, _| {}).unwrap();
    film.pixels[0]
}

fn assert_close(got: Color, want: Color) {
    assert!((got - want).abs().max_element() <= 1e-4 * want.abs().max_element().max(1.0), "got {got}, want {want}");
}

#[test]
fn analytic_diffuse_sphere_under_point_light() {
    // Sphere of radius 2 at the origin, light at (0, 0, 6): the camera ray hits (0, 0, 2) head-on, 4 away
    // from the light. Radiance = ka*Ia + kd * cos(0) * I / d².
    let m = material(0.25, 0.5, MaterialKind::BlinnPhong);
    let sphere = object(ShapeDesc::Sphere { center: Vec3::ZERO, radius: 2.0 }, 0);
    let light = LightDesc::Point { position: Vec3::new(0.0, 0.0, 6.0), intensity: Color::splat(1600.0) };
    let got = pixel(scene(vec![m], vec![sphere], vec![light], 0));
    assert_close(got, Color::splat(0.25 * 100.0 + 0.5 * 1600.0 / 16.0));
}

#[test]
fn analytic_light_behind_occluder_leaves_only_ambient() {
    let m = material(0.25, 0.5, MaterialKind::BlinnPhong);
    let sphere = object(ShapeDesc::Sphere { center: Vec3::ZERO, radius: 2.0 }, 0);
    let blocker = object(quad(4.0, 0.5, false), 0);
    let light = LightDesc::Point { position: Vec3::new(0.0, 0.0, 6.0), intensity: Color::splat(1600.0) };
    // The camera sits between the blocker (z = 4) and the sphere (surface at z = 2), under the blocker's
    // shadow: the point it sees gets no direct light.
    let mut desc = scene(vec![m], vec![sphere, blocker], vec![light], 0);
    desc.cameras[0].position = Vec3::new(0.0, 0.0, 3.0);
    assert_close(pixel(desc), Color::splat(25.0));
}

#[test]
fn analytic_back_face_is_lit_by_the_light_in_front_of_it() {
    // A square at z = 0 whose stored normal faces away from the camera. The METU renderers shade it with
    // that normal from both sides: the light in front of it (z = -4) lights its back, seen by the
    // camera; a light on the camera's side does not. Turning normals to the ray swaps the two.
    let m = material(0.25, 0.5, MaterialKind::BlinnPhong);
    let light = |z: f32| LightDesc::Point { position: Vec3::new(0.0, 0.0, z), intensity: Color::splat(1600.0) };
    let back = |z: f32, flip: bool| {
        let mut desc = scene(vec![m.clone()], vec![object(quad(0.0, 5.0, false), 0)], vec![light(z)], 0);
        desc.flip_back_faces = flip;
        pixel(desc)
    };
    let (ambient, lit) = (Color::splat(25.0), Color::splat(25.0 + 0.5 * 1600.0 / 16.0));
    assert_close(back(-4.0, false), lit);
    assert_close(back(4.0, false), ambient);
    assert_close(back(-4.0, true), ambient);
    assert_close(back(4.0, true), lit);
}

#[test]
fn analytic_mirror_seen_from_behind_reflects_from_its_front() {
    // A mirror at z = 0 whose stored normal faces away from the camera, a wall at z = -20 in front of
    // it, nothing behind the camera. The METU renderers offset the reflected ray along the stored
    // normal: it starts in front of the mirror, meets the mirror's front face right away and reflects
    // from there to the wall: mirror ambient + km (mirror ambient + km * wall ambient). Turned to the
    // ray, the reflection leaves towards the camera and sees nothing.
    let mirror = material(0.1, 0.0, MaterialKind::Mirror { reflectance: Color::splat(0.5) });
    let wall = material(0.8, 0.0, MaterialKind::BlinnPhong);
    let seen = |flip: bool| {
        let objects = vec![object(quad(0.0, 5.0, false), 0), object(quad(-20.0, 50.0, true), 1)];
        let mut desc = scene(vec![mirror.clone(), wall.clone()], objects, vec![], 2);
        desc.flip_back_faces = flip;
        pixel(desc)
    };
    assert_close(seen(false), Color::splat(10.0 + 0.5 * (10.0 + 0.5 * 80.0)));
    assert_close(seen(true), Color::splat(10.0));
}

#[test]
fn analytic_mirror_returns_what_is_behind_the_camera() {
    // A mirror at z = 0 facing the camera; behind the camera at z = 20 a wall facing it, lit only by
    // ambient light. Seen: mirror ambient + km * wall ambient.
    let mirror = material(0.1, 0.0, MaterialKind::Mirror { reflectance: Color::new(0.5, 0.25, 1.0) });
    let wall = material(0.8, 0.0, MaterialKind::BlinnPhong);
    let objects = vec![object(quad(0.0, 5.0, true), 0), object(quad(20.0, 50.0, false), 1)];
    let got = pixel(scene(vec![mirror, wall], objects, vec![], 1));
    assert_close(got, Color::splat(10.0) + Color::new(0.5, 0.25, 1.0) * 80.0);
}

#[test]
fn analytic_recursion_limit_zero_disables_reflection() {
    let mirror = material(0.1, 0.0, MaterialKind::Mirror { reflectance: Color::ONE });
    let wall = material(0.8, 0.0, MaterialKind::BlinnPhong);
    let objects = vec![object(quad(0.0, 5.0, true), 0), object(quad(20.0, 50.0, false), 1)];
    assert_close(pixel(scene(vec![mirror, wall], objects, vec![], 0)), Color::splat(10.0));
}

#[test]
fn analytic_conductor_at_normal_incidence() {
    let (n, k) = (0.37f32, 2.82f32);
    let km = Color::new(1.0, 0.86, 0.57);
    let metal = material(0.0, 0.0, MaterialKind::Conductor { reflectance: km, eta: n, k });
    let wall = material(0.8, 0.0, MaterialKind::BlinnPhong);
    let objects = vec![object(quad(0.0, 5.0, true), 0), object(quad(20.0, 50.0, false), 1)];
    let fr = ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
    assert_close(pixel(scene(vec![metal, wall], objects, vec![], 1)), km * fr * 80.0);
}

#[test]
fn analytic_glass_slab_with_beers_law() {
    // A slab between z = 1 and z = -1 (thickness 2), a wall at z = -10 facing the camera. At normal
    // incidence each interface transmits 1 - F, F = ((n-1)/(n+1))²; inside, Beer's law keeps e^(-c*2).
    // With depth 2 the ray reaches the wall after two refractions; internal reflections see only the
    // glass's own (zero) ambient, and the front reflection escapes to the black background.
    let eta = 1.5f32;
    let c = Color::new(0.1, 0.2, 0.05);
    let glass = material(0.0, 0.0, MaterialKind::Dielectric { eta, absorption: c });
    let wall = material(0.8, 0.0, MaterialKind::BlinnPhong);
    let objects =
        vec![object(quad(1.0, 5.0, true), 0), object(quad(-1.0, 5.0, false), 0), object(quad(-10.0, 50.0, true), 1)];
    let f = ((eta - 1.0) / (eta + 1.0)).powi(2);
    let beer = (-c * 2.0).exp();
    let want = beer * (1.0 - f) * (1.0 - f) * 80.0;
    assert_close(pixel(scene(vec![glass, wall], objects, vec![], 2)), want);
}

#[test]
fn analytic_render_is_identical_for_any_thread_count() {
    let m = material(0.25, 0.5, MaterialKind::BlinnPhong);
    let sphere = object(ShapeDesc::Sphere { center: Vec3::ZERO, radius: 2.0 }, 0);
    let light = LightDesc::Area {
        position: Vec3::new(0.0, 5.0, 5.0),
        normal: Vec3::new(0.0, -1.0, -1.0).normalize(),
        size: 2.0,
        radiance: Color::splat(400.0),
    };
    let mut desc = scene(vec![m], vec![sphere], vec![light], 0);
    desc.cameras[0].width = 48;
    desc.cameras[0].height = 40;
    desc.cameras[0].window = Window { left: -0.3, right: 0.3, bottom: -0.25, top: 0.25 };
    desc.cameras[0].num_samples = 9;
    let s = Scene::build(desc, &AccelConfig::default(), None).unwrap();
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| render(&s, 0, &RenderOptions::default(), &|_, _| {}).unwrap().0)
    };
    assert_eq!(run(1).pixels, run(3).pixels);
}

#[test]
fn analytic_environment_seen_directly_and_in_a_mirror() {
    use arbor::film::Film;
    use arbor::light::environment::EnvMap;
    // A lat-long map that is red in the -z half (the centre of the image) and blue elsewhere.
    let (w, h) = (64, 32);
    let mut film = Film::new(w, h);
    for y in 0..h {
        for x in 0..w {
            let red = (w / 4..3 * w / 4).contains(&x);
            film.pixels[(y * w + x) as usize] = if red { Color::new(0.8, 0.0, 0.0) } else { Color::new(0.0, 0.0, 0.6) };
        }
    }
    let env = || Some(EnvMap::from_film_latlong(film.clone()));
    // Nothing in the scene: the camera looks down -z and sees red, in display units whatever the scale.
    let mut desc = scene(vec![], vec![], vec![], 0);
    desc.radiance_scale = 1.0 / 255.0;
    let s = Scene::build(desc, &AccelConfig::default(), env()).unwrap();
    let (direct, _) = render(&s, 0, &RenderOptions::default(), &|_, _| {}).unwrap();
    assert_close(direct.pixels[0], Color::new(0.8, 0.0, 0.0));
    // A mirror facing the camera sends the ray back along +z: blue, times the mirror's reflectance.
    let mirror = material(0.0, 0.0, MaterialKind::Mirror { reflectance: Color::splat(0.5) });
    let desc = scene(vec![mirror], vec![object(quad(0.0, 5.0, true), 0)], vec![], 1);
    let s = Scene::build(desc, &AccelConfig::default(), env()).unwrap();
    let (reflected, _) = render(&s, 0, &RenderOptions::default(), &|_, _| {}).unwrap();
    assert_close(reflected.pixels[0], Color::new(0.0, 0.0, 0.3));
}

#[test]
fn analytic_glass_is_not_shaded_from_inside() {
    // The glass slab of the Beer's law test, now with ambient reflectance: only the front face, seen
    // from outside, adds it; the back face, met from inside, only refracts.
    let eta = 1.5f32;
    let mut glass = material(0.3, 0.0, MaterialKind::Dielectric { eta, absorption: Color::ZERO });
    glass.diffuse = Color::ZERO;
    let wall = material(0.8, 0.0, MaterialKind::BlinnPhong);
    let objects =
        vec![object(quad(1.0, 5.0, true), 0), object(quad(-1.0, 5.0, false), 0), object(quad(-10.0, 50.0, true), 1)];
    let f = ((eta - 1.0) / (eta + 1.0)).powi(2);
    let want = Color::splat(30.0) + (1.0 - f) * (1.0 - f) * Color::splat(80.0);
    assert_close(pixel(scene(vec![glass, wall], objects, vec![], 2)), want);
}

#[test]
fn analytic_scene_without_shadows_lights_occluded_points() {
    // The occluder scene again, with shadow rays off (the NYU convention): the full diffuse term returns.
    let m = material(0.25, 0.5, MaterialKind::BlinnPhong);
    let sphere = object(ShapeDesc::Sphere { center: Vec3::ZERO, radius: 2.0 }, 0);
    let blocker = object(quad(4.0, 0.5, false), 0);
    let light = LightDesc::Point { position: Vec3::new(0.0, 0.0, 6.0), intensity: Color::splat(1600.0) };
    let mut desc = scene(vec![m], vec![sphere, blocker], vec![light], 0);
    desc.cameras[0].position = Vec3::new(0.0, 0.0, 3.0);
    desc.shadows = false;
    assert_close(pixel(desc), Color::splat(25.0 + 0.5 * 1600.0 / 16.0));
}

#[test]
fn render_refuses_an_image_too_large_for_memory_before_tracing() {
    let mut desc = scene(vec![material(1.0, 0.0, MaterialKind::BlinnPhong)], vec![], vec![], 0);
    (desc.cameras[0].width, desc.cameras[0].height) = (4_000_000, 4_000_000);
    let s = Scene::build(desc, &AccelConfig::default(), None).unwrap();
    let traced = std::sync::atomic::AtomicBool::new(false);
    let progress = |_: u64, _: u64| traced.store(true, std::sync::atomic::Ordering::Relaxed);
    // 1.6e13 pixels: 12 bytes each in the film, 48 in the exact sums.
    let e = render(&s, 0, &RenderOptions::default(), &progress).unwrap_err();
    assert_eq!(e.to_string(), "not enough memory for a 4000000x4000000 image (178813.9 GiB)");
    let e = arbor::render::render_sums(&s, 0, &RenderOptions::default(), &progress).unwrap_err();
    assert_eq!(e.to_string(), "not enough memory for a 4000000x4000000 image (715255.7 GiB)");
    assert!(e.is_io(), "exit 4, as the other resources the machine lacks");
    assert!(!traced.into_inner(), "refused before any tile was traced");
}

#[test]
fn analytic_camera_ray_sees_the_radiance_of_an_emitter_on_its_front_only() {
    // A black light mesh facing the camera shows its radiance (plus nothing: no ambient, no diffuse);
    // turned away, its back is dark; a black light sphere shows its radiance too.
    let black = material(0.0, 0.0, MaterialKind::BlinnPhong);
    let emitter = |shape| ObjectDesc { emission: Some(Color::new(1.0, 2.0, 3.0)), ..object(shape, 0) };
    let lit = |o: ObjectDesc| {
        let s = Scene::build(scene(vec![black.clone()], vec![o], Vec::new(), 0), &AccelConfig::default(), None);
        let s = s.unwrap();
        assert_eq!(s.light_of(0), Some(0), "the emitter is the scene's light 0");
        let (film, _) = render(&s, 0, &RenderOptions::default(), &|_, _| {}).unwrap();
        film.pixels[0]
    };
    assert_close(lit(emitter(quad(0.0, 1.0, true))), Color::new(1.0, 2.0, 3.0));
    assert_close(lit(emitter(quad(0.0, 1.0, false))), Color::ZERO);
    assert_close(lit(emitter(ShapeDesc::Sphere { center: Vec3::ZERO, radius: 1.0 })), Color::new(1.0, 2.0, 3.0));
}
