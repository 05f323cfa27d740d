//! The debug views: primitive-id images byte-identical across every structure (on a generated mesh and
//! on every shared reference scene whose files are present), the heatmap's cost, legend and maximum,
//! the normal view's colours, and where box wireframes land.

mod common;

use std::path::Path;
use std::time::Instant;

use arbor::accel::{AccelConfig, AccelKind, TraversalCounts};
use arbor::bench::{framing_camera, mesh_scene, primary_rays, sphere_mesh};
use arbor::film::Film;
use arbor::geometry::TriangleMesh;
use arbor::integrator::debug::{false_color, legend_rows, overlay_boxes, BOX_COLOR};
use arbor::integrator::DebugView;
use arbor::math::{Aabb, Color, Vec3};
use arbor::render::{render, RenderOptions};
use arbor::scene::{build_camera, load_desc, CameraDesc, Scene, SceneDesc, ShapeDesc, Window};

/// Primitive tests (plus nodes) one structure may spend on one reference-scene image; beyond it (brute
/// force on large scenes) only an evenly spaced sample of pixels is compared.
const WORK_BUDGET: f64 = 1e8;

fn debug_render(desc: &SceneDesc, kind: AccelKind, view: DebugView) -> (Film, Option<u32>) {
    let scene = Scene::build(desc.clone(), &AccelConfig::from(kind), None).unwrap_or_else(|e| panic!("{e}"));
    let opts = RenderOptions { debug: Some(view), ..Default::default() };
    let (film, stats) = render(&scene, 0, &opts, &|_, _| {}).unwrap();
    (film, stats.heatmap_max)
}

/// A camera at `z` looking down -z at the origin, `n x n` pixels, window `±half` at distance 1.
fn straight_camera(z: f32, half: f32, n: u32) -> CameraDesc {
    let mut cam = framing_camera(Aabb::new(Vec3::splat(-1.0), Vec3::ONE), n, n);
    cam.position = Vec3::new(0.0, 0.0, z);
    cam.gaze = -Vec3::Z;
    cam.up = Vec3::Y;
    cam.window = Window { left: -half, right: half, bottom: -half, top: half };
    cam.near_distance = 1.0;
    cam
}

#[test]
fn debug_primid_identical_across_structures_on_generated_mesh() {
    let mesh = sphere_mesh(6000);
    let desc = mesh_scene(mesh.clone(), Path::new("sphere"), framing_camera(mesh.bounds(), 64, 48));
    let (reference, _) = debug_render(&desc, AccelKind::BvhSah, DebugView::PrimId);
    let bytes = reference.to_rgb8();
    let distinct: std::collections::HashSet<_> = bytes.chunks(3).collect();
    assert!(distinct.len() > 500, "only {} colours: the view does not tell primitives apart", distinct.len());
    for &kind in AccelKind::ALL {
        let (film, _) = debug_render(&desc, kind, DebugView::PrimId);
        assert!(film.to_rgb8() == bytes, "{kind}: primid image differs from bvh-sah's");
    }
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let (alone, _) = pool.install(|| debug_render(&desc, AccelKind::BvhSah, DebugView::PrimId));
    assert!(alone.to_rgb8() == bytes, "primid image depends on the thread count");
}

/// Estimated work of a primid render: the mean traversal cost of a sample of the camera's rays times
/// the pixel count.
fn estimated_work(scene: &Scene) -> f64 {
    let rays = primary_rays(&scene.cameras[0]);
    let step = (rays.len() / 64).max(1);
    let mut counts = TraversalCounts::default();
    let mut n = 0;
    for r in rays.iter().step_by(step) {
        scene.geometry.intersect_counted(r, f32::INFINITY, &mut counts);
        n += 1;
    }
    (counts.nodes as f64 + counts.prims as f64) / n.max(1) as f64 * rays.len() as f64
}

#[test]
fn debug_primid_identical_across_structures_on_reference_scenes() {
    let Some(dir) = common::scenes_dir() else { return };
    let start = Instant::now();
    let mut scenes = common::scene_files(&dir.join("ceng795-2024-hw1/hw1/inputs"), "xml");
    scenes.extend(common::scene_files(&dir.join("ceng795-2025-json/hw1/inputs"), "json"));
    let (mut compared, mut skipped, mut failures, mut sampled_note) = (0, Vec::new(), Vec::new(), Vec::new());
    for path in &scenes {
        let mut desc = load_desc(path).unwrap_or_else(|e| panic!("{e}"));
        if !common::missing_mesh_files(&desc).is_empty() || desc.cameras.is_empty() {
            skipped.push(format!("{} (missing mesh file or camera)", path.display()));
            continue;
        }
        // The window does not depend on the resolution: a quarter-size image shows the same view.
        let cam = &mut desc.cameras[0];
        (cam.width, cam.height) = ((cam.width / 4).max(8), (cam.height / 4).max(8));
        let (reference, _) = debug_render(&desc, AccelKind::BvhSah, DebugView::PrimId);
        let bytes = reference.to_rgb8();
        for &kind in AccelKind::ALL.iter().filter(|&&k| k != AccelKind::BvhSah) {
            let scene = Scene::build(desc.clone(), &AccelConfig::from(kind), None).unwrap_or_else(|e| panic!("{e}"));
            let work = estimated_work(&scene);
            compared += 1;
            if work > WORK_BUDGET {
                // Too slow for the whole image (brute force on large scenes): every pixel depends on its
                // own camera ray only, so compare an evenly spaced sample of pixels, byte for byte.
                let stride = (work / WORK_BUDGET).sqrt().ceil() as u32;
                let cam = &desc.cameras[0];
                let camera = arbor::scene::build_camera(cam);
                // Culled as `render` culls without an option: as the scene (or its form) says.
                let cull = scene.cull_backfaces.unwrap_or(false);
                let integrator = arbor::integrator::DebugIntegrator::new(&scene, DebugView::PrimId, cull);
                let mut sampled = 0;
                for y in (0..cam.height).step_by(stride as usize) {
                    for x in (0..cam.width).step_by(stride as usize) {
                        let ray = camera.ray(x, y, arbor::math::Vec2::splat(0.5), arbor::math::Vec2::ZERO);
                        let got = integrator.li_camera(&ray).to_array().map(arbor::film::quantize);
                        let at = 3 * (y * cam.width + x) as usize;
                        sampled += 1;
                        if got[..] != bytes[at..at + 3] {
                            failures.push(format!("{kind} on {} at pixel ({x}, {y})", path.display()));
                        }
                    }
                }
                sampled_note
                    .push(format!("{kind} on {}: {sampled} pixels (one in {stride} along each axis)", path.display()));
                continue;
            }
            let opts = RenderOptions { debug: Some(DebugView::PrimId), ..Default::default() };
            let (film, _) = render(&scene, 0, &opts, &|_, _| {}).unwrap();
            if film.to_rgb8() != bytes {
                failures.push(format!("{kind} on {}", path.display()));
            }
        }
    }
    for s in &skipped {
        println!("SKIPPED {s}");
    }
    for s in &sampled_note {
        println!("SAMPLED {s}");
    }
    println!("{compared} primid images compared with bvh-sah's in {:.1} s", start.elapsed().as_secs_f64());
    assert!(scenes.len() >= 20, "only {} reference scenes found", scenes.len());
    assert!(compared >= 20, "only {compared} images compared");
    assert!(failures.is_empty(), "primid images differ from bvh-sah's:\n{}", failures.join("\n"));
}

#[test]
fn debug_heatmap_costs_more_where_geometry_is_dense_and_has_legend() {
    // Left half: a 40x40 grid of small triangles; right half: one quad.
    let mut mesh = TriangleMesh::default();
    let n = 40;
    for j in 0..=n {
        for i in 0..=n {
            mesh.positions.push(Vec3::new(-1.0 + i as f32 / n as f32, -1.0 + 2.0 * j as f32 / n as f32, 0.0));
        }
    }
    for j in 0..n {
        for i in 0..n {
            let v = j * (n + 1) + i;
            mesh.indices.push([v, v + 1, v + n + 2]);
            mesh.indices.push([v, v + n + 2, v + n + 1]);
        }
    }
    let base = mesh.positions.len() as u32;
    mesh.positions.extend([Vec3::new(0.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 0.0)]);
    mesh.positions.push(Vec3::new(0.0, 1.0, 0.0));
    mesh.indices.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
    let size = 64;
    let desc = mesh_scene(mesh, Path::new("half.obj"), straight_camera(3.0, 0.34, size));
    let (film, max) = debug_render(&desc, AccelKind::BvhSah, DebugView::Heatmap);
    let max = max.expect("the heatmap reports its maximum");
    assert!(max > 0);
    let legend = legend_rows(size);
    // Redness grows with cost along the ramp's second half; compare the mean "warmth" (red - blue).
    let warmth = |x0: u32, x1: u32| {
        let mut sum = 0.0;
        for y in 0..size - legend {
            for x in x0..x1 {
                let c = film.get(x, y);
                sum += c.x - c.z;
            }
        }
        sum / ((x1 - x0) * (size - legend)) as f32
    };
    assert!(warmth(0, size / 2) > warmth(size / 2, size) + 0.1, "{} vs {}", warmth(0, 32), warmth(32, 64));
    // The most expensive pixel maps to the top of the ramp.
    assert!((0..size - legend).any(|y| (0..size).any(|x| film.get(x, y) == false_color(1.0))));
    // The legend: every row of the bar runs through the ramp from left to right.
    for y in size - legend..size {
        assert_eq!(film.get(0, y), false_color(0.0));
        assert_eq!(film.get(size - 1, y), false_color(1.0));
        assert_eq!(film.get(size / 2, y), false_color((size / 2) as f32 / (size - 1) as f32));
    }
}

fn sphere_scene(size: u32) -> SceneDesc {
    let mut desc = mesh_scene(TriangleMesh::default(), Path::new("sphere.xml"), straight_camera(5.0, 0.5, size));
    desc.objects[0].shape = ShapeDesc::Sphere { center: Vec3::ZERO, radius: 1.0 };
    desc
}

#[test]
fn debug_normal_of_sphere_centre_faces_the_camera() {
    let (film, _) = debug_render(&sphere_scene(21), AccelKind::BvhSah, DebugView::Normal);
    let c = film.get(10, 10);
    assert!(c.abs_diff_eq(Color::new(0.5, 0.5, 1.0), 1e-4), "{c}");
    assert_eq!(film.get(0, 0), Color::ZERO);
    // Right of centre the normal leans to +x, above it to +y.
    assert!(film.get(13, 10).x > 0.55 && film.get(10, 7).y > 0.55);
}

#[test]
fn debug_boxes_land_where_edges_project_and_nowhere_else() {
    let cam = straight_camera(5.0, 1.0, 100);
    let mut film = Film::new(100, 100);
    // The cube's front face (distance 4) spans pixels 37.5..62.5; its back face (distance 6) 41.7..58.3.
    let cam = build_camera(&cam);
    overlay_boxes(&mut film, &cam, &[Aabb::new(Vec3::splat(-1.0), Vec3::ONE)], BOX_COLOR);
    for (x, y) in [(37, 50), (62, 50), (50, 37), (50, 62), (41, 50), (58, 50), (39, 39)] {
        assert_eq!(film.get(x, y), BOX_COLOR, "no edge at ({x}, {y})");
    }
    for (x, y) in [(50, 50), (45, 50), (40, 50), (60, 50), (10, 10), (36, 50), (63, 50), (50, 30)] {
        assert_eq!(film.get(x, y), Color::ZERO, "unexpected edge at ({x}, {y})");
    }
    for y in 0..100 {
        for x in 0..100 {
            if film.get(x, y) == BOX_COLOR {
                assert!((37..=62).contains(&x) && (37..=62).contains(&y), "edge outside the cube at ({x}, {y})");
            }
        }
    }
    // A box behind the camera draws nothing; one around the camera draws without panicking.
    let mut behind = Film::new(100, 100);
    overlay_boxes(&mut behind, &cam, &[Aabb::new(Vec3::new(-1.0, -1.0, 6.0), Vec3::new(1.0, 1.0, 8.0))], BOX_COLOR);
    assert!(behind.pixels.iter().all(|&c| c == Color::ZERO));
    overlay_boxes(&mut behind, &cam, &[Aabb::new(Vec3::splat(-10.0), Vec3::splat(10.0))], BOX_COLOR);
}

#[test]
fn debug_boxes_view_draws_the_structure_over_the_render() {
    let desc = sphere_scene(32);
    let (root, _) = debug_render(&desc, AccelKind::BvhSah, DebugView::Boxes { depth: 0 });
    assert!(root.pixels.contains(&BOX_COLOR), "the root box is not drawn");
    let (none, _) = debug_render(&desc, AccelKind::BvhSah, DebugView::Boxes { depth: 60 });
    assert!(!none.pixels.contains(&BOX_COLOR), "boxes drawn below the deepest level");
}

#[test]
fn debug_boxes_depth_is_the_depth_the_statistics_report() {
    // `arbor info` and the render summary show `accel_stats().max_depth`: the deepest level the view
    // draws, for every structure, in a scene of a mesh (its own structure) and a sphere (the top level
    // then holds two objects).
    let mesh = sphere_mesh(6000);
    let mut desc = mesh_scene(mesh.clone(), Path::new("sphere"), framing_camera(mesh.bounds(), 64, 48));
    let mut ball = desc.objects[0].clone();
    ball.name = "ball".into();
    ball.shape = ShapeDesc::Sphere { center: Vec3::new(3.0, 0.0, 0.0), radius: 0.5 };
    desc.objects.push(ball);
    for &kind in AccelKind::ALL {
        let scene = Scene::build(desc.clone(), &AccelConfig::from(kind), None).unwrap();
        let deepest = scene.geometry.accel_stats().max_depth;
        assert!(deepest > 1 || kind == AccelKind::Brute, "{kind}: depth max {deepest} tests nothing");
        for d in 0..=deepest {
            assert!(!scene.geometry.boxes_at_depth(d).is_empty(), "{kind}: no box at depth {d} of {deepest}");
        }
        assert!(scene.geometry.boxes_at_depth(deepest + 1).is_empty(), "{kind}: boxes below depth max {deepest}");
    }
}
