//! Path-traced scenes against their official images (CENG 795 2022 hw6 `pathTracing`, `veach-ajar`, and
//! the 2019 hw6 `pathTracing` scenes), by project issue 31's rule for noisy references
//! ([`arbor::image_io::noisy`]): each camera is rendered at the reference's N samples with seeds 1 and 2;
//! on 16x16 block means in display levels the seed-1 render must be as close to the reference as to the
//! seed-2 render, plus 1 level, with every channel's mean signed difference within 2 levels. Where the
//! official EXR is there, the blocks are means of radiance put through one curve the reference EXR fixes
//! ([`arbor::image_io::levels`]); the 2019 references are PNGs only, compared PNG to PNG, the renders
//! shown through their camera's tone curve under the one exposure that fits the reference
//! ([`compare_noisy_tonemapped`]): the official PNG's exposure came from its renderer's own noisy
//! log-average, as a render's would from its own (docs/reference-results.md measures both).
//!
//! A PNG's tone curve takes its burn-out white from the whole image, so a PNG-only reference is always
//! compared with whole-frame renders: a window tone-mapped on its own is exposed differently (it put
//! the 2019 references 23 to 61 levels off).
//!
//! The ignored `reference_path_tracing` takes every camera at its own samples N over the whole frame,
//! but for cameras of more than [`WHOLE_FRAME_SAMPLES`] samples (Veach's scene, 2500 per pixel), which it
//! compares over the central [`CROP`]-pixel window; the ignored `reference_path_tracing_full` takes the
//! whole frame of every camera. `reference_path_tracing_window`, part of the default run, takes the
//! 2022 Cornell boxes' eight cameras without Russian roulette over the central [`QUICK_CROP`]-pixel
//! window ([`without_roulette`] says why not the others). `ARBOR_PT_SAMPLES=N`
//! lowers N (a quicker, less faithful run) and `ARBOR_PT_ONLY=TEXT` keeps the cameras whose image name
//! contains TEXT. The cameras in [`KNOWN_FAILURES`] fail for reasons measured and written down in
//! docs/reference-results.md; they are reported and not counted.

mod common;

use std::path::{Path, PathBuf};
use std::time::Instant;

use arbor::accel::AccelConfig;
use arbor::film::Film;
use arbor::image_io::noisy::{compare_noisy_hdr, compare_noisy_rgb8, compare_noisy_tonemapped, NoisyComparison};
use arbor::image_io::read_image;
use arbor::render::{render, RenderOptions};
use arbor::renderer::{PathOptions, Renderer, Roulette};
use arbor::scene::{load_desc, Scene};

/// Side of the central window of cameras of many samples, in pixels.
const CROP: u32 = 128;
/// Side of the central window of the quick test, in pixels.
const QUICK_CROP: u32 = 128;
/// Most samples (pixels x samples per pixel) of a camera rendered whole by `reference_path_tracing`: the
/// Cornell boxes' 512x512 at 100.
const WHOLE_FRAME_SAMPLES: u64 = 512 * 512 * 100;
/// Block side of the comparison.
const BLOCK: u32 = 16;
/// The references the rule fails on for a measured reason (docs/reference-results.md, "What fails"),
/// under the scenes folder: their rows are printed as `known FAIL` and not counted. One that passes at
/// its own samples fails the run, so that this list and the docs follow it.
const KNOWN_FAILURES: &[&str] = &[
    // The official image has 2.5 to 4 times Arbor's count of pixels above 100 (fireflies).
    "ceng795-2022/hw6/pathTracing/outputs/diffuse_next_importance_russian.png",
    // At the rule's margin with the course's roulette (infinite variance): over seed pairs (1,2), (3,4),
    // (5,6) these fail 2 and 1 of 3, and failed 1 and 0 of 3 with the sampler before d3c2e33.
    "ceng795-2019/inputs/hw6/pathTracing/diffuse_russian.png",
    "ceng795-2019/inputs/hw6/pathTracing/glass_importance_russian.png",
];

/// One camera of a scene file and its reference image.
struct Case {
    scene: PathBuf,
    camera: usize,
    reference: PathBuf,
}

/// Every path-tracing camera of the scene files in `inputs` whose image (as PNG) is in `outputs` and
/// whose options `keep` accepts; the others with a reference are returned as skipped.
fn cases(inputs: &Path, outputs: &Path, keep: fn(&PathOptions) -> bool) -> (Vec<Case>, Vec<String>) {
    let (mut found, mut skipped) = (Vec::new(), Vec::new());
    let mut files: Vec<PathBuf> = std::fs::read_dir(inputs)
        .unwrap_or_else(|e| panic!("{}: {e}", inputs.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "xml"))
        .collect();
    files.sort();
    for scene in files {
        let desc = match load_desc(&scene) {
            Ok(d) => d,
            Err(e) => {
                skipped.push(format!("{} ({e})", scene.display()));
                continue;
            }
        };
        for (i, cam) in desc.cameras.iter().enumerate() {
            let Renderer::PathTracing(options) = cam.renderer else { continue };
            let reference = outputs.join(Path::new(&cam.image_name).with_extension("png"));
            let only = std::env::var("ARBOR_PT_ONLY").unwrap_or_default();
            if !cam.image_name.contains(only.as_str()) {
                continue;
            }
            if !keep(&options) {
                continue;
            }
            if reference.is_file() {
                found.push(Case { scene: scene.clone(), camera: i, reference });
            } else {
                skipped.push(format!("{} camera {} (no {})", scene.display(), cam.id, reference.display()));
            }
        }
    }
    (found, skipped)
}

/// The window `crop` of `film`.
fn window(film: &Film, crop: (u32, u32, u32, u32)) -> Film {
    let (x0, y0, x1, y1) = crop;
    let pixels = (y0..y1).flat_map(|y| (x0..x1).map(move |x| film.get(x, y))).collect();
    Film { width: x1 - x0, height: y1 - y0, pixels }
}

/// The rule on the window `crop` of the reference and the two seeds' renders of that window: in radiance
/// against the official EXR when there is one, else 8-bit as the camera writes its image.
fn judge(
    scene: &Scene,
    camera: usize,
    reference: &Path,
    crop: (u32, u32, u32, u32),
    films: [&Film; 2],
) -> NoisyComparison {
    let exr = reference.with_extension("exr");
    if exr.is_file() {
        let official = read_image(&exr).unwrap_or_else(|e| panic!("{e}"));
        // The film holds radiance times the scene's radiance scale.
        let radiance = |f: &Film| Film { pixels: f.pixels.iter().map(|&c| c / scene.radiance_scale).collect(), ..*f };
        return compare_noisy_hdr(&window(&official, crop), &radiance(films[0]), &radiance(films[1]), BLOCK);
    }
    // An 8-bit image read as a film holds its levels over 255, which `to_rgb8` gives back exactly.
    let official = window(&read_image(reference).unwrap_or_else(|e| panic!("{e}")), crop).to_rgb8();
    match scene.cameras[camera].tonemap {
        // The reference's exposure came from its own noise: both seeds under the one that fits it.
        Some(t) => compare_noisy_tonemapped(&official, &t, films[0], films[1], BLOCK),
        None => {
            let (cw, ch) = (crop.2 - crop.0, crop.3 - crop.1);
            compare_noisy_rgb8(&official, &films[0].to_rgb8(), &films[1].to_rgb8(), cw, ch, BLOCK)
        }
    }
}

/// Which part of each camera's frame a run renders.
#[derive(Clone, Copy, PartialEq)]
enum Scope {
    /// The whole frame, at the camera's own samples.
    Whole,
    /// The whole frame up to [`WHOLE_FRAME_SAMPLES`], the central [`CROP`] window beyond.
    Budget,
    /// The central window of this side.
    Window(u32),
}

/// Renders and judges every case over `scope` (a PNG-only reference: always the whole frame).
fn run(title: &str, cases: Vec<Case>, skipped: Vec<String>, scope: Scope) -> Vec<String> {
    let mut failures = Vec::new();
    println!("## {title}\n\n| scene | camera | image | N | window | exposure | render vs reference | seed vs seed | bias R G B | result | render s |\n|---|---|---|---|---|---|---|---|---|---|---|");
    let mut current: Option<(PathBuf, Scene)> = None;
    for case in cases {
        if current.as_ref().is_none_or(|(p, _)| *p != case.scene) {
            let desc = load_desc(&case.scene).unwrap_or_else(|e| panic!("{e}"));
            current = Some((case.scene.clone(), Scene::build(desc, &AccelConfig::default(), None).unwrap()));
        }
        let scene = &current.as_ref().unwrap().1;
        let cam = &scene.cameras[case.camera];
        let (w, h) = (cam.width, cam.height);
        let fewer = std::env::var("ARBOR_PT_SAMPLES").ok().and_then(|v| v.parse().ok());
        let n = if scope == Scope::Whole { cam.num_samples } else { cam.num_samples.min(fewer.unwrap_or(u32::MAX)) };
        let png_only = !case.reference.with_extension("exr").is_file();
        let side = match scope {
            _ if png_only => None,
            Scope::Whole => None,
            Scope::Budget if u64::from(w) * u64::from(h) * u64::from(n) <= WHOLE_FRAME_SAMPLES => None,
            Scope::Budget => Some(CROP),
            Scope::Window(side) => Some(side),
        };
        let crop = match side {
            None => (0, 0, w, h),
            Some(side) => {
                let (cw, ch) = (side.min(w), side.min(h));
                ((w - cw) / 2, (h - ch) / 2, (w - cw) / 2 + cw, (h - ch) / 2 + ch)
            }
        };
        let start = Instant::now();
        let film = |seed: u64| {
            let opts = RenderOptions { spp: Some(n), seed, crop: Some(crop), ..Default::default() };
            render(scene, case.camera, &opts, &|_, _| {}).unwrap().0
        };
        let (a, b) = (film(1), film(2));
        let secs = start.elapsed().as_secs_f64();
        let c = judge(scene, case.camera, &case.reference, crop, [&a, &b]);
        let (cw, ch) = (crop.2 - crop.0, crop.3 - crop.1);
        let name = case.scene.file_name().unwrap().to_string_lossy().to_string();
        let compared = if png_only { case.reference.clone() } else { case.reference.with_extension("exr") };
        let image = compared.file_name().unwrap().to_string_lossy().to_string();
        let known = KNOWN_FAILURES.iter().any(|k| case.reference.ends_with(k));
        let result = match (c.passes(), known) {
            (true, _) => "OK",
            (false, true) => "known FAIL",
            (false, false) => "FAIL",
        };
        println!(
            "| {name} | {} | {image} | {n} | {cw}x{ch} | {} | {:.2} | {:.2} | {:+.2} {:+.2} {:+.2} | {result} | {secs:.1} |",
            cam.id,
            c.exposure.map_or("reference's".to_string(), |k| format!("{k:.3} x own")),
            c.mad, c.noise, c.bias[0], c.bias[1], c.bias[2],
        );
        if !c.passes() && !known {
            failures.push(format!("{name} camera {} -> {image}: {}", cam.id, c.summary()));
        }
        if c.passes() && known && n == cam.num_samples {
            failures.push(format!("{name} camera {} -> {image} passes: take it off KNOWN_FAILURES", cam.id));
        }
    }
    for s in skipped {
        println!("SKIPPED {s}");
    }
    failures
}

/// Runs the sets `sets` picks from the shared scenes over `scope` and fails with every camera that fails.
fn run_sets(sets: fn(&Path) -> Vec<Set>, scope: Scope) {
    let Some(dir) = common::scenes_dir() else { return };
    let mut failures = Vec::new();
    for (title, (cases, skipped)) in sets(&dir) {
        failures.extend(run(title, cases, skipped, scope));
    }
    assert!(failures.is_empty(), "{} failed:\n{}", failures.len(), failures.join("\n"));
}

/// A titled set of cases and the cameras skipped.
type Set = (&'static str, (Vec<Case>, Vec<String>));

/// The 2022 Cornell boxes (`hw6/pathTracing`) whose cameras `keep` accepts.
fn cornell_2022(dir: &Path, keep: fn(&PathOptions) -> bool) -> Set {
    let hw6 = dir.join("ceng795-2022/hw6/pathTracing");
    ("CENG 795 2022 hw6 path tracing", cases(&hw6.join("inputs"), &hw6.join("outputs"), keep))
}

/// Every set: the 2022 and 2019 Cornell boxes and Veach's scene.
fn every_set(dir: &Path) -> Vec<Set> {
    let veach = dir.join("ceng795-2022/hw6/veach-ajar");
    let old = dir.join("ceng795-2019/inputs/hw6/pathTracing");
    vec![
        cornell_2022(dir, |_| true),
        ("CENG 795 2019 hw6 path tracing", cases(&old, &old, |_| true)),
        ("CENG 795 2022 hw6 veach-ajar", cases(&veach.join("inputs"), &veach.join("outputs"), |_| true)),
    ]
}

/// The quick subset: the 2022 Cornell boxes' cameras without Russian roulette. The course's roulette is
/// an estimator of infinite variance (a path that survives k vertices is divided by about π^(k(k+1)/2)):
/// over a window of 64 blocks its fireflies move a channel's mean by ±4 levels from seed to seed, so its
/// cameras are judged on the whole frame only.
fn without_roulette(dir: &Path) -> Vec<Set> {
    vec![cornell_2022(dir, |o| o.roulette == Roulette::Off)]
}

#[test]
fn reference_path_tracing_window() {
    run_sets(without_roulette, Scope::Window(QUICK_CROP));
}

#[test]
#[ignore = "about 20 minutes on two cores: 33 cameras, two seeds each, Veach's at 2500 samples"]
fn reference_path_tracing() {
    run_sets(every_set, Scope::Budget);
}

#[test]
#[ignore = "every camera at its own samples over the whole frame: hours on two cores"]
fn reference_path_tracing_full() {
    run_sets(every_set, Scope::Whole);
}
