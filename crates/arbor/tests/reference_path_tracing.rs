//! Path-traced scenes against their official images (CENG 795 2022 hw6 `pathTracing`, `veach-ajar`, and
//! the 2019 hw6 `pathTracing` scenes), by project issue 17's rule for noisy references
//! ([`arbor::image_io::noisy`]): each camera is rendered at four times N samples (seed 1) and at N
//! samples with seeds 1 and 2; on 16x16 block means of the tone-mapped images the first must be as
//! close to the reference as the two seeds are to each other, plus 1 level, with every channel's mean
//! signed difference within 2 levels. The three renders are tone-mapped with the exposure of the
//! reference EXR (its log-average and burn-out white, from which the official PNG was made): the
//! photographic operator takes both from the image itself, so a render's own noise (its fireflies, its
//! black pixels) would shift its exposure and bias the comparison by several levels.
//!
//! `reference_path_tracing` takes every camera at its own samples N (as the rule asks: a reference's
//! noise is that of its samples, and the tone curve turns a noisier image darker or brighter in block
//! means) over the central [`CROP`]-pixel window; the ignored `reference_path_tracing_full` takes the
//! whole frame. `ARBOR_PT_SAMPLES=N` lowers N (a quicker, less faithful run) and `ARBOR_PT_ONLY=TEXT`
//! keeps the cameras whose image name contains TEXT.

mod common;

use std::path::{Path, PathBuf};
use std::time::Instant;

use arbor::accel::AccelConfig;
use arbor::film::Film;
use arbor::image_io::noisy::compare_noisy_rgb8;
use arbor::image_io::{read_image, read_rgb8};
use arbor::render::{render, RenderOptions};
use arbor::renderer::Renderer;
use arbor::scene::{load_desc, Scene};

/// Side of the default test's central window, in pixels.
const CROP: u32 = 128;
/// Block side of the comparison.
const BLOCK: u32 = 16;

/// One camera of a scene file and its reference image.
struct Case {
    scene: PathBuf,
    camera: usize,
    reference: PathBuf,
}

/// Every path-tracing camera of the scene files in `inputs` whose image (as PNG) is in `outputs`; the
/// others are returned as skipped.
fn cases(inputs: &Path, outputs: &Path) -> (Vec<Case>, Vec<String>) {
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
            if !matches!(cam.renderer, Renderer::PathTracing(_)) {
                continue;
            }
            let reference = outputs.join(Path::new(&cam.image_name).with_extension("png"));
            let only = std::env::var("ARBOR_PT_ONLY").unwrap_or_default();
            if !cam.image_name.contains(only.as_str()) {
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

/// The window `crop` of `rgb` (`width` wide), row-major RGB.
fn window(rgb: &[u8], width: u32, crop: (u32, u32, u32, u32)) -> Vec<u8> {
    let (x0, y0, x1, y1) = crop;
    (y0..y1)
        .flat_map(|y| (x0..x1).map(move |x| 3 * (y * width + x) as usize))
        .flat_map(|i| rgb[i..i + 3].to_vec())
        .collect()
}

/// The 8-bit image of `film`: under the reference's exposure when the camera tone-maps and the reference
/// EXR is there (so that the noise of a render does not move its own exposure), else as the camera
/// writes it.
fn shown(scene: &Scene, camera: usize, film: &Film, reference_exr: Option<&Film>) -> Vec<u8> {
    match (scene.cameras[camera].tonemap, reference_exr) {
        (Some(t), Some(exr)) => {
            // The official EXR holds the scene's radiance; the film holds it times the radiance scale.
            let unscaled = film.pixels.iter().map(|&c| c / scene.radiance_scale).collect();
            let scene_units = Film { width: film.width, height: film.height, pixels: unscaled };
            let t = t.in_units(1.0);
            t.apply_exposure(&scene_units, t.exposure(exr)).to_rgb8()
        }
        (Some(t), None) => t.apply(film).to_rgb8(),
        (None, _) => film.to_rgb8(),
    }
}

/// Renders and judges every case; `full`: each camera's own samples over the whole frame.
fn run(title: &str, cases: Vec<Case>, skipped: Vec<String>, full: bool) -> Vec<String> {
    let mut failures = Vec::new();
    println!("## {title}\n\n| scene | camera | image | N | window | converged vs reference | seed vs seed | bias R G B | N-sample bias | result | render s |\n|---|---|---|---|---|---|---|---|---|---|---|");
    let mut current: Option<(PathBuf, Scene)> = None;
    for case in cases {
        if current.as_ref().is_none_or(|(p, _)| *p != case.scene) {
            let desc = load_desc(&case.scene).unwrap_or_else(|e| panic!("{e}"));
            current = Some((case.scene.clone(), Scene::build(desc, &AccelConfig::default(), None).unwrap()));
        }
        let scene = &current.as_ref().unwrap().1;
        let cam = &scene.cameras[case.camera];
        let (w, h, reference) = read_rgb8(&case.reference).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!((w, h), (cam.width, cam.height), "{}", case.reference.display());
        let fewer = std::env::var("ARBOR_PT_SAMPLES").ok().and_then(|v| v.parse().ok());
        let n = if full { cam.num_samples } else { cam.num_samples.min(fewer.unwrap_or(u32::MAX)) };
        let crop = if full {
            (0, 0, w, h)
        } else {
            let (cw, ch) = (CROP.min(w), CROP.min(h));
            ((w - cw) / 2, (h - ch) / 2, (w - cw) / 2 + cw, (h - ch) / 2 + ch)
        };
        let start = Instant::now();
        let exr = case.reference.with_extension("exr");
        let exr = exr.is_file().then(|| read_image(&exr).unwrap_or_else(|e| panic!("{e}")));
        let film = |spp: u32, seed: u64| {
            let opts = RenderOptions { spp: Some(spp), seed, crop: Some(crop), ..Default::default() };
            let full = render(scene, case.camera, &opts, &|_, _| {}).unwrap().0;
            shown(scene, case.camera, &full, exr.as_ref())
        };
        let (converged, a, b) = (film(4 * n, 1), film(n, 1), film(n, 2));
        let secs = start.elapsed().as_secs_f64();
        let (cw, ch) = (crop.2 - crop.0, crop.3 - crop.1);
        let reference = window(&reference, w, crop);
        let c = compare_noisy_rgb8(&reference, &converged, &a, &b, cw, ch, BLOCK);
        // The seed-1 render at the reference's own samples: where a converged render differs from a
        // noisy reference only through the tone curve's non-linearity, this one has no bias.
        let same_n = compare_noisy_rgb8(&reference, &a, &a, &b, cw, ch, BLOCK).bias;
        let name = case.scene.file_name().unwrap().to_string_lossy().to_string();
        let image = case.reference.file_name().unwrap().to_string_lossy().to_string();
        println!(
            "| {name} | {} | {image} | {n} | {cw}x{ch} | {:.2} | {:.2} | {:+.2} {:+.2} {:+.2} | {:+.2} {:+.2} {:+.2} | {} | {secs:.1} |",
            cam.id,
            c.mad,
            c.noise,
            c.bias[0],
            c.bias[1],
            c.bias[2],
            same_n[0],
            same_n[1],
            same_n[2],
            if c.passes() { "OK" } else { "FAIL" }
        );
        if !c.passes() {
            failures.push(format!("{name} camera {} -> {image}: {}", cam.id, c.summary()));
        }
    }
    for s in skipped {
        println!("SKIPPED {s}");
    }
    failures
}

/// Runs every set ([`run`]'s `full`) and fails with every camera that fails.
fn run_sets(full: bool) {
    let Some(dir) = common::scenes_dir() else { return };
    let mut failures = Vec::new();
    for (title, (cases, skipped)) in sets(&dir) {
        failures.extend(run(title, cases, skipped, full));
    }
    assert!(failures.is_empty(), "{} failed:\n{}", failures.len(), failures.join("\n"));
}

/// A titled set of cases and the cameras skipped.
type Set = (&'static str, (Vec<Case>, Vec<String>));

fn sets(dir: &Path) -> Vec<Set> {
    let hw6 = dir.join("ceng795-2022/hw6");
    let old = dir.join("ceng795-2019/inputs/hw6/pathTracing");
    vec![
        ("CENG 795 2022 hw6 path tracing", cases(&hw6.join("pathTracing/inputs"), &hw6.join("pathTracing/outputs"))),
        ("CENG 795 2019 hw6 path tracing", cases(&old, &old)),
        ("CENG 795 2022 hw6 veach-ajar", cases(&hw6.join("veach-ajar/inputs"), &hw6.join("veach-ajar/outputs"))),
    ]
}

#[test]
#[ignore = "minutes, and issue 17 open: Veach's scene and the four next-event Cornell cameras match; the \
            Russian roulette references are brighter than the unbiased answer and the plain cameras fail \
            in display space (see docs/reference-results.md)"]
fn reference_path_tracing() {
    run_sets(false);
}

#[test]
#[ignore = "every camera at its own samples over the whole frame: hours on two cores"]
fn reference_path_tracing_full() {
    run_sets(true);
}
