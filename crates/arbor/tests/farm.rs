//! Farm slices merge back into the single-process image bit for bit: tiles of a fixed grid (4 and 9),
//! sample ranges (4 = 1+3 = 2+2 = 1+1+1+1; 16 = 5+1+10 with every distribution effect), both at once, through partial EXR files on disk; and the
//! merge refuses parts that do not fit together, with messages naming the file.

use std::path::{Path, PathBuf};

use arbor::accel::AccelConfig;
use arbor::farm::{decode_partial, encode_partial, merge, read_partial, tile_window, write_partial, Partial};
use arbor::film::Film;
use arbor::render::{render, render_sums, RenderOptions};
use arbor::renderer::{PathOptions, Renderer, Roulette};
use arbor::sampler::SamplerKind;
use arbor::scene::{parse_desc, Scene, SceneLimits};
use arbor::tonemap::Tonemap;

fn example() -> Scene {
    let text = include_str!("../../../examples/cornell_box.xml");
    let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/cornell_box.xml"));
    let mut desc = parse_desc(text, path).unwrap_or_else(|e| panic!("{e}"));
    for c in &mut desc.cameras {
        (c.width, c.height) = (c.width / 8, c.height / 8 + 3);
    }
    assert_eq!(desc.cameras[0].num_samples, 4);
    Scene::build(desc, &AccelConfig::default(), None).unwrap()
}

fn bits(film: &Film) -> Vec<u32> {
    film.pixels.iter().flat_map(|c| c.to_array()).map(f32::to_bits).collect()
}

/// Renders the slice, writes it as a partial EXR in `dir`, reads it back.
fn part(scene: &Scene, dir: &Path, tile: Option<(u32, u32)>, samples: (u32, u32)) -> (PathBuf, Partial) {
    part_with(scene, dir, tile, samples, &RenderOptions::default())
}

/// [`part`] with the render's other options from `base`.
fn part_with(
    scene: &Scene,
    dir: &Path,
    tile: Option<(u32, u32)>,
    samples: (u32, u32),
    base: &RenderOptions,
) -> (PathBuf, Partial) {
    let cam = &scene.cameras[0];
    let crop = tile.map(|(i, n)| tile_window(i, n, cam.width, cam.height).unwrap());
    let opts = RenderOptions { crop, samples: Some(samples), ..base.clone() };
    let (sums, stats) = render_sums(scene, 0, &opts, &|_, _| {}).unwrap();
    assert_eq!(stats.samples, samples);
    let name = format!("part-{:?}-{}-{}.exr", tile.unwrap_or((0, 1)), samples.0, samples.1);
    let path = dir.join(name);
    let tonemap = Some(Tonemap { key: 0.3, burn_percent: 2.5, saturation: 0.8, gamma: 1.8, ..Tonemap::PREVIEW });
    let p = Partial { identity: "example".into(), camera: cam.id.clone(), tonemap, sums };
    write_partial(&path, &p).unwrap();
    let back = read_partial(&path, &SceneLimits::default().rendered()).unwrap();
    assert_eq!(back, p, "{}", path.display());
    (path, back)
}

#[test]
fn farm_tiles_and_sample_ranges_merge_to_the_whole() {
    let scene = example();
    let dir = tempfile::tempdir().unwrap();
    let whole = render(&scene, 0, &RenderOptions::default(), &|_, _| {}).unwrap().0;
    let splits: [&[(u32, u32)]; 4] =
        [&[(0, 4)], &[(0, 1), (1, 4)], &[(2, 4), (0, 2)], &[(3, 4), (0, 1), (2, 3), (1, 2)]];
    for n in [1, 4, 9] {
        for ranges in splits {
            let parts: Vec<_> = (0..n)
                .flat_map(|i| ranges.iter().map(move |&r| (i, r)))
                .map(|(i, r)| part(&scene, dir.path(), Some((i, n)), r))
                .collect();
            let merged = merge(&parts).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(bits(&merged), bits(&whole), "{n} tiles, samples {ranges:?}");
            assert_eq!(merged.to_rgb8(), whole.to_rgb8());
        }
    }
}

#[test]
fn farm_path_tracer_sample_ranges_merge_to_the_whole() {
    // The stratified sampler spreads a pixel's light and bounce samples over all its samples: a slice of
    // them must draw what the whole render draws for the same samples.
    let scene = example();
    let dir = tempfile::tempdir().unwrap();
    // The course's cameras (its roulette) also split at the example's glass.
    for (sampler, roulette) in [
        (SamplerKind::Stratified, Roulette::Off),
        (SamplerKind::Independent, Roulette::Off),
        (SamplerKind::Sobol, Roulette::Off),
        (SamplerKind::Stratified, Roulette::Course),
    ] {
        let split_refraction = roulette == Roulette::Course;
        let options =
            PathOptions { importance_sampling: true, next_event: true, mis: true, roulette, split_refraction };
        let renderer = Some(Renderer::PathTracing(options));
        let base = RenderOptions { renderer, sampler, ..Default::default() };
        let whole = render(&scene, 0, &base, &|_, _| {}).unwrap().0;
        for n in [1, 4] {
            let parts: Vec<_> = (0..n)
                .flat_map(|i| [(0, 1), (1, 3), (3, 4)].into_iter().map(move |r| (i, r)))
                .map(|(i, r)| part_with(&scene, dir.path(), Some((i, n)), r, &base))
                .collect();
            let merged = merge(&parts).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(bits(&merged), bits(&whole), "{sampler:?}, {roulette:?}, {n} tiles");
        }
    }
}

#[test]
fn farm_distribution_effects_merge_to_the_whole() {
    // Depth of field, motion blur, glossy rays and an area light at 16 samples per pixel, split into
    // tiles and uneven sample ranges.
    let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/distribution.xml"));
    let mut desc = arbor::scene::load_desc(path).unwrap_or_else(|e| panic!("{e}"));
    for c in &mut desc.cameras {
        (c.width, c.height) = (c.width / 8, c.height / 8 + 1);
    }
    assert_eq!(desc.cameras[0].num_samples, 16);
    let scene = Scene::build(desc, &AccelConfig::default(), None).unwrap();
    assert!(scene.geometry.has_motion());
    let dir = tempfile::tempdir().unwrap();
    let whole = render(&scene, 0, &RenderOptions::default(), &|_, _| {}).unwrap().0;
    for n in [1, 4] {
        let parts: Vec<_> = (0..n)
            .flat_map(|i| [(0, 5), (5, 6), (6, 16)].into_iter().map(move |r| (i, r)))
            .map(|(i, r)| part(&scene, dir.path(), Some((i, n)), r))
            .collect();
        let merged = merge(&parts).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(bits(&merged), bits(&whole), "{n} tiles");
    }
}

#[test]
fn farm_merge_refuses_parts_that_do_not_fit() {
    let scene = example();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let name = |p: &(PathBuf, Partial)| p.0.display().to_string();
    let err = |parts: &[(PathBuf, Partial)]| merge(parts).map(|_| ()).unwrap_err().to_string();

    let t: Vec<_> = (0..4).map(|i| part(&scene, d, Some((i, 4)), (0, 4))).collect();
    assert_eq!(
        err(&t[..3]),
        format!(
            "the parts do not cover pixel ({}, {}): no part has its samples 0..4",
            t[3].1.sums.window.0, t[3].1.sums.window.1
        )
    );
    let mut twice = t.clone();
    twice.push(t[2].clone());
    let (x, y) = (t[2].1.sums.window.0, t[2].1.sums.window.1);
    let msg = format!("{}: samples 0..4 of pixel ({x}, {y}) are also in {}", name(&t[2]), name(&t[2]));
    assert_eq!(err(&twice), msg);

    let a = part(&scene, d, None, (0, 2));
    let b = part(&scene, d, None, (1, 4));
    let c = part(&scene, d, None, (3, 4));
    assert_eq!(
        err(&[a.clone(), b.clone()]),
        format!("{}: samples 1..4 of pixel (0, 0) are also in {}", name(&b), name(&a))
    );
    assert_eq!(err(&[a.clone(), c]), "the parts do not cover pixel (0, 0): no part has its samples 2..3");
    assert_eq!(err(std::slice::from_ref(&a)), "the parts do not cover pixel (0, 0): no part has its samples 2..4");

    let mut other = part(&scene, d, None, (2, 4));
    other.1.identity = "another scene".into();
    let msg =
        format!("{}: not from the same render as {} (the scene, camera or options differ)", name(&other), name(&a));
    assert_eq!(err(&[a.clone(), other]), msg);
    let mut spp = part(&scene, d, None, (2, 4));
    spp.1.sums.spp = 8;
    let msg = format!("{}: not from the same render as {} (the samples per pixel differ)", name(&spp), name(&a));
    assert_eq!(err(&[a.clone(), spp]), msg);
    let mut scale = part(&scene, d, None, (2, 4));
    scale.1.sums.scale *= 2.0;
    let msg = format!("{}: not from the same render as {} (the radiance scale differs)", name(&scale), name(&a));
    assert_eq!(err(&[a.clone(), scale]), msg);

    // A slice whose window leaves its frame is refused when read.
    let mut wide = a.1.clone();
    let (w, h) = wide.sums.frame;
    wide.sums.frame = (w - 1, h);
    let path = d.join("wide.exr");
    write_partial(&path, &wide).unwrap();
    let e = read_partial(&path, &SceneLimits::default().rendered()).unwrap_err().to_string();
    let msg = format!("the data window ({w} x {h} pixels at (0, 0)) is not inside the {} x {h} frame", w - 1);
    assert_eq!(e, format!("{}: {msg}", path.display()));
}

#[test]
fn farm_partial_writes_the_same_bytes_every_time() {
    // The exr crate writes a header's own attributes in a HashMap's order, which changes from map to
    // map: the header is put in name order after, so that a render written twice is the same file.
    let scene = example();
    let dir = tempfile::tempdir().unwrap();
    let (path, p) = part(&scene, dir.path(), None, (0, 4));
    let first = encode_partial(&path, &p).unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), first);
    for _ in 0..8 {
        assert_eq!(encode_partial(&path, &p).unwrap(), first);
    }
    assert_eq!(decode_partial(&first, &path, &SceneLimits::default().rendered()).unwrap(), p);
}

#[test]
fn farm_read_partial_refuses_a_plain_exr() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("plain.exr");
    arbor::image_io::write_image(&path, &Film::new(3, 2)).unwrap();
    let e = read_partial(&path, &SceneLimits::default().rendered()).unwrap_err().to_string();
    assert_eq!(e, format!("{}: not a partial image of `arbor render` (no arbor.render attribute)", path.display()));
}
