//! Reproducible images: the same scene gives the same bits for any thread count and any tile order, and a
//! crop equals the same window of the full render.
//!
//! Every shared reference scene (the enumeration of `reference_scenes.rs`: the 2024 XML set, the 2025
//! JSON set, the NYU bunny) is rendered at a third of its resolution (the image-plane window does not
//! depend on the resolution) on a pool of 1 and of 2 rayon threads, and the films compared bit for bit.
//! Several samples per pixel with an area light (random numbers in every pixel) are covered by the
//! 2019 `cornellbox_area.xml` and the project's own Cornell box; every random choice of distribution ray
//! tracing (lens, time, glossy rays) and the seed by the project's `distribution.xml`. Tile order: a film assembled from
//! one-tile crops rendered in reverse order equals the full render.

mod common;

use std::path::Path;

use arbor::accel::AccelConfig;
use arbor::film::Film;
use arbor::render::{render, RenderOptions};
use arbor::renderer::{PathOptions, Renderer, Roulette};
use arbor::scene::{load_desc, parse_desc, Scene, SceneDesc};

const DIVISOR: u32 = 3;

fn shrink(mut desc: SceneDesc, divisor: u32) -> SceneDesc {
    for c in &mut desc.cameras {
        c.width = (c.width / divisor).max(1);
        c.height = (c.height / divisor).max(1);
    }
    desc
}

fn render_on(threads: usize, scene: &Scene, camera: usize, opts: &RenderOptions) -> Film {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| render(scene, camera, opts, &|_, _| {}).unwrap().0)
}

fn bits(film: &Film) -> Vec<u32> {
    film.pixels.iter().flat_map(|c| c.to_array()).map(f32::to_bits).collect()
}

/// Renders every camera of `desc` with 1 and 2 threads; returns the names of those that differ.
fn compare_threads(name: &str, desc: SceneDesc, opts: &RenderOptions) -> Vec<String> {
    let scene = Scene::build(desc, &AccelConfig::default(), None).unwrap_or_else(|e| panic!("{e}"));
    let mut differ = Vec::new();
    for camera in 0..scene.cameras.len() {
        for cull in [false, true] {
            let opts = RenderOptions { cull_backfaces: Some(cull), ..opts.clone() };
            let one = render_on(1, &scene, camera, &opts);
            let two = render_on(2, &scene, camera, &opts);
            if bits(&one) != bits(&two) || one.to_rgb8() != two.to_rgb8() {
                differ.push(format!("{name} camera {camera} culling {cull}"));
            }
        }
    }
    differ
}

#[test]
fn reproducible_shared_scenes_for_1_and_2_threads() {
    let Some(dir) = common::scenes_dir() else { return };
    let mut scenes = common::scene_files(&dir.join("ceng795-2024-hw1/hw1/inputs"), "xml");
    scenes.extend(common::scene_files(&dir.join("ceng795-2025-json/hw1/inputs"), "json"));
    let (mut differ, mut rendered) = (Vec::new(), 0);
    for path in &scenes {
        let desc = load_desc(path).unwrap_or_else(|e| panic!("{e}"));
        if !common::missing_mesh_files(&desc).is_empty() {
            println!("SKIPPED {} (missing meshes)", path.display());
            continue;
        }
        rendered += 1;
        differ.extend(compare_threads(&path.display().to_string(), shrink(desc, DIVISOR), &RenderOptions::default()));
    }
    assert!(rendered >= 15, "only {rendered} scenes rendered");

    // The NYU bunny, as reference_scenes.rs sets it up (scene.json names a missing dragon).
    let data = dir.join("nyu-cg-assignment4/Assignment_4/data");
    let text = std::fs::read_to_string(data.join("scene.json")).unwrap();
    let bunny = data.join("bunny.off").canonicalize().unwrap();
    let text = text.replace("\"dragon.off\"", &serde_json::to_string(&bunny.display().to_string()).unwrap());
    let tmp = tempfile::tempdir().unwrap();
    let scene = tmp.path().join("bunny.json");
    std::fs::write(&scene, text).unwrap();
    let desc = load_desc(&scene).unwrap_or_else(|e| panic!("{e}"));
    differ.extend(compare_threads("NYU bunny", shrink(desc, DIVISOR), &RenderOptions::default()));
    assert!(differ.is_empty(), "1 and 2 threads give different images:\n{}", differ.join("\n"));
}

#[test]
fn reproducible_area_light_with_many_samples() {
    let Some(dir) = common::scenes_dir() else { return };
    let path = dir.join("ceng795-2019/inputs/hw2/cornellbox_area.xml");
    let desc = load_desc(&path).unwrap_or_else(|e| panic!("{e}"));
    assert!(common::missing_mesh_files(&desc).is_empty());
    let opts = RenderOptions { spp: Some(4), ..Default::default() };
    let differ = compare_threads("cornellbox_area", shrink(desc, 8), &opts);
    assert!(differ.is_empty(), "{differ:?}");
}

fn example() -> Scene {
    let text = include_str!("../../../examples/cornell_box.xml");
    let desc = parse_desc(text, Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/cornell_box.xml")));
    let desc = shrink(desc.unwrap_or_else(|e| panic!("{e}")), 4);
    assert!(desc.cameras[0].num_samples > 1);
    Scene::build(desc, &AccelConfig::default(), None).unwrap()
}

/// The distribution ray tracing example (area light, glossy metal and glass, depth of field, moving
/// objects: every random choice of a sample), at a quarter of its size.
fn distribution() -> Scene {
    let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/distribution.xml"));
    let desc = shrink(load_desc(path).unwrap_or_else(|e| panic!("{e}")), 4);
    assert!(desc.cameras[0].num_samples > 1);
    Scene::build(desc, &AccelConfig::default(), None).unwrap()
}

#[test]
fn reproducible_distribution_effects_for_threads_crops_and_seeds() {
    let scene = distribution();
    assert!(scene.geometry.has_motion());
    let seeded = |seed| RenderOptions { seed, ..Default::default() };
    let full = render_on(2, &scene, 0, &seeded(7));
    assert_eq!(bits(&full), bits(&render_on(1, &scene, 0, &seeded(7))), "1 and 2 threads");
    let crop = (5, 9, 61, 40);
    let part = render_on(1, &scene, 0, &RenderOptions { crop: Some(crop), ..seeded(7) });
    assert_eq!(bits(&part), window(&full, crop), "crop");
    // Another seed draws other samples: most pixels change (noise), none by much on average.
    let other = render_on(2, &scene, 0, &seeded(8));
    let changed = full.pixels.iter().zip(&other.pixels).filter(|(a, b)| a != b).count();
    assert!(changed * 2 > full.pixels.len(), "only {changed} of {} pixels differ between seeds", full.pixels.len());
    let mean = |f: &Film| f.pixels.iter().map(|c| c.element_sum() as f64).sum::<f64>() / f.pixels.len() as f64;
    assert!((mean(&full) - mean(&other)).abs() < 0.01 * mean(&full), "{} vs {}", mean(&full), mean(&other));
}

/// The pixels `x0..x1` x `y0..y1` of `film`.
fn window(film: &Film, (x0, y0, x1, y1): (u32, u32, u32, u32)) -> Vec<u32> {
    let mut out = Vec::new();
    for y in y0..y1 {
        for x in x0..x1 {
            out.extend(film.get(x, y).to_array().map(f32::to_bits));
        }
    }
    out
}

#[test]
fn reproducible_example_for_thread_counts_and_crops() {
    let scene = example();
    let opts = RenderOptions::default();
    let full = render_on(2, &scene, 0, &opts);
    assert_eq!(bits(&full), bits(&render_on(1, &scene, 0, &opts)));
    let (w, h) = (full.width, full.height);
    // Aligned to tiles, not aligned, one pixel, one row, the whole frame, and past the frame (clamped).
    for crop in [(16, 32, 48, 64), (7, 13, 61, 29), (50, 50, 51, 51), (0, 99, 100, 100), (0, 0, w, h)] {
        let opts = RenderOptions { crop: Some(crop), ..Default::default() };
        let part = render_on(2, &scene, 0, &opts);
        assert_eq!((part.width, part.height), (crop.2 - crop.0, crop.3 - crop.1), "{crop:?}");
        assert_eq!(bits(&part), window(&full, crop), "crop {crop:?}");
    }
    let clamped = render_on(1, &scene, 0, &RenderOptions { crop: Some((90, 95, 500, 500)), ..Default::default() });
    assert_eq!(bits(&clamped), window(&full, (90, 95, w, h)));

    // Tile order: every 16x16 tile rendered alone, last tile first, on one thread.
    let mut assembled = Film::new(w, h);
    let tiles: Vec<(u32, u32)> =
        (0..h.div_ceil(16)).flat_map(|ty| (0..w.div_ceil(16)).map(move |tx| (tx, ty))).collect();
    for &(tx, ty) in tiles.iter().rev() {
        let crop = (tx * 16, ty * 16, ((tx + 1) * 16).min(w), ((ty + 1) * 16).min(h));
        let part = render_on(1, &scene, 0, &RenderOptions { crop: Some(crop), ..Default::default() });
        for y in crop.1..crop.3 {
            for x in crop.0..crop.2 {
                assembled.pixels[(y * w + x) as usize] = part.get(x - crop.0, y - crop.1);
            }
        }
    }
    assert_eq!(bits(&assembled), bits(&full), "tiles rendered in reverse order");
}

#[test]
fn reproducible_course_roulette_for_thread_counts_and_crops() {
    // The course's roulette draws a number only where a survival is uncertain, and the course's split at
    // the glass traces its branches in a fixed order: still one stream per sample.
    let scene = example();
    let options = PathOptions {
        importance_sampling: true,
        next_event: true,
        roulette: Roulette::Course,
        mis: false,
        split_refraction: true,
    };
    let opts = RenderOptions { renderer: Some(Renderer::PathTracing(options)), spp: Some(4), ..Default::default() };
    let full = render_on(2, &scene, 0, &opts);
    assert_eq!(bits(&full), bits(&render_on(1, &scene, 0, &opts)));
    let crop = (7, 13, 61, 29);
    let part = render_on(2, &scene, 0, &RenderOptions { crop: Some(crop), ..opts.clone() });
    assert_eq!(bits(&part), window(&full, crop));
}

#[test]
fn reproducible_render_stops_when_cancelled() {
    let scene = example();
    let cancel = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(true));
    let opts = RenderOptions { cancel: Some(cancel), ..Default::default() };
    let (film, stats) = render(&scene, 0, &opts, &|_, _| {}).unwrap();
    assert!(stats.cancelled);
    assert_eq!(stats.rays, 0);
    assert!(film.pixels.iter().all(|c| *c == arbor::math::Color::ZERO));
}
