//! The course scenes against their official reference images.
//!
//! Every scene of the 2024 XML set, the 2025 JSON set and the NYU bunny is rendered and compared with
//! its reference: at most 0.5% of pixels may differ by more than 8 levels in any channel. The 2024 set
//! has references without back-face culling (`outputs_nobfc/`), compared with an unculled render, and
//! with it (`outputs/`), compared with a culled render wherever the two references differ. The 2025
//! references are the culled ones. A scene whose mesh files are missing is skipped, by name.
//!
//! Each test writes its results as a Markdown table to `$CARGO_TARGET_TMPDIR` (collected into
//! `docs/reference-results.md`).

mod common;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use arbor::accel::AccelConfig;
use arbor::image_io::metrics::compare_rgb8;
use arbor::image_io::read_rgb8;
use arbor::render::{render, RenderOptions};
use arbor::scene::{load_desc, Scene};

const THRESHOLD: u8 = 8;
const MAX_SHARE_OFF: f64 = 0.005;

/// One image to render and compare.
struct Case {
    scene: PathBuf,
    camera: usize,
    reference: PathBuf,
    cull: bool,
}

/// The reference of camera `camera` of `scene` in `outputs` (same sub-folder, image name as PNG).
fn reference_for(inputs: &Path, outputs: &Path, scene: &Path, image_name: &str) -> PathBuf {
    let rel = scene.parent().unwrap().strip_prefix(inputs).unwrap();
    outputs.join(rel).join(Path::new(image_name).with_extension("png"))
}

/// Renders and compares every case; returns the table and the failures.
fn run(title: &str, cases: Vec<Case>, skipped: Vec<String>) -> (String, Vec<String>) {
    let mut table = format!(
        "## {title}\n\n| scene | image | culling | size | PSNR dB | pixels off > {THRESHOLD} | max diff | render s |\n\
         |---|---|---|---|---|---|---|---|\n"
    );
    let mut failures = Vec::new();
    let mut current: Option<(PathBuf, Scene)> = None;
    for case in cases {
        if current.as_ref().is_none_or(|(p, _)| *p != case.scene) {
            let desc = load_desc(&case.scene).unwrap_or_else(|e| panic!("{e}"));
            let scene = Scene::build(desc, &AccelConfig::default(), None).unwrap_or_else(|e| panic!("{e}"));
            current = Some((case.scene.clone(), scene));
        }
        let scene = &current.as_ref().unwrap().1;
        let start = Instant::now();
        let opts = RenderOptions { cull_backfaces: Some(case.cull), ..Default::default() };
        let (film, _) = render(scene, case.camera, &opts, &|_, _| {}).unwrap();
        let secs = start.elapsed().as_secs_f64();
        let name = case.scene.file_name().unwrap().to_string_lossy().to_string();
        let image = case.reference.file_name().unwrap().to_string_lossy().to_string();
        let (w, h, reference) = read_rgb8(&case.reference).unwrap_or_else(|e| panic!("{e}"));
        if (w, h) != (film.width, film.height) {
            failures.push(format!("{name} -> {image}: rendered {}x{}, reference {w}x{h}", film.width, film.height));
            continue;
        }
        let c = compare_rgb8(&reference, &film.to_rgb8(), w, h, THRESHOLD);
        let _ = writeln!(
            table,
            "| {name} | {image} | {} | {w}x{h} | {:.2} | {:.3}% | {} | {secs:.2} |",
            if case.cull { "on" } else { "off" },
            c.psnr,
            c.share_off * 100.0,
            c.max_diff
        );
        println!("{name} -> {image} (culling {}): {} in {secs:.2} s", case.cull, c.summary());
        if c.share_off > MAX_SHARE_OFF {
            failures.push(format!(
                "{name} -> {image} (culling {}): {:.3}% of pixels off by more than {THRESHOLD} (limit {:.1}%)",
                case.cull,
                c.share_off * 100.0,
                MAX_SHARE_OFF * 100.0
            ));
        }
    }
    for s in skipped {
        println!("SKIPPED {s}");
        let _ = writeln!(table, "| {s} | | | | | | | |");
    }
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("reference-{}.md", title.replace(' ', "-")));
    std::fs::write(&out, &table).unwrap();
    println!("{table}");
    (table, failures)
}

fn check(failures: Vec<String>) {
    assert!(failures.is_empty(), "images differ from their references:\n{}", failures.join("\n"));
}

/// Cases of one METU set: every scene file under `inputs`, each camera against its reference(s).
fn metu_cases(root: &Path, ext: &str, refs: &[(&str, bool)]) -> (Vec<Case>, Vec<String>) {
    let inputs = root.join("inputs");
    let (mut cases, mut skipped) = (Vec::new(), Vec::new());
    for scene in common::scene_files(&inputs, ext) {
        let desc = load_desc(&scene).unwrap_or_else(|e| panic!("{e}"));
        let missing = common::missing_mesh_files(&desc);
        if !missing.is_empty() {
            let names: Vec<String> = missing.iter().map(|p| p.display().to_string()).collect();
            skipped.push(format!("{} (missing {})", scene.display(), names.join(", ")));
            continue;
        }
        for (camera, cam) in desc.cameras.iter().enumerate() {
            let mut previous: Option<Vec<u8>> = None;
            for &(outputs, cull) in refs {
                let reference = reference_for(&inputs, &root.join(outputs), &scene, &cam.image_name);
                let Ok(bytes) = std::fs::read(&reference) else { continue };
                // A second reference identical to the first adds nothing but render time.
                if previous.as_ref().is_some_and(|p| *p == bytes) {
                    continue;
                }
                previous = Some(bytes);
                cases.push(Case { scene: scene.clone(), camera, reference, cull });
            }
        }
    }
    (cases, skipped)
}

#[test]
fn reference_ceng795_2024_xml() {
    let Some(dir) = common::scenes_dir() else { return };
    let (cases, skipped) =
        metu_cases(&dir.join("ceng795-2024-hw1/hw1"), "xml", &[("outputs_nobfc", false), ("outputs", true)]);
    assert!(cases.len() >= 15, "only {} cases found", cases.len());
    check(run("CENG 795 2024 XML", cases, skipped).1);
}

#[test]
fn reference_ceng795_2025_json() {
    let Some(dir) = common::scenes_dir() else { return };
    let (cases, skipped) = metu_cases(&dir.join("ceng795-2025-json/hw1"), "json", &[("outputs", true)]);
    assert!(cases.len() >= 15, "only {} cases found", cases.len());
    check(run("CENG 795 2025 JSON", cases, skipped).1);
}

#[test]
fn reference_nyu_bunny() {
    let Some(dir) = common::scenes_dir() else { return };
    let data = dir.join("nyu-cg-assignment4/Assignment_4/data");
    // The reference shows bunny.off under scene.json's camera, lights and material; scene.json itself
    // names the dragon, whose file is missing. Point a copy of the scene at the bunny.
    let text = std::fs::read_to_string(data.join("scene.json")).unwrap();
    let bunny = data.join("bunny.off").canonicalize().unwrap();
    let text = text.replace("\"dragon.off\"", &serde_json::to_string(&bunny.display().to_string()).unwrap());
    let tmp = tempfile::tempdir().unwrap();
    let scene = tmp.path().join("bunny.json");
    std::fs::write(&scene, text).unwrap();
    let reference = dir.join("nyu-cg-assignment4/Assignment_4/img/bunny.png");
    let cases = vec![Case { scene, camera: 0, reference, cull: false }];
    check(run("NYU bunny", cases, Vec::new()).1);
}
