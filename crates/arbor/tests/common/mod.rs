//! Helpers shared by the integration tests: where the shared real-world data lives, and random
//! triangle soups (`soups.rs`).
#![allow(dead_code)]

pub mod soups;

use std::path::{Path, PathBuf};

use arbor::scene::{MeshSource, SceneDesc, ShapeDesc};

/// The folder of shared reference scenes: `$ARBOR_SCENES`, or `../shared/scenes` beside the checkout.
///
/// Returns `None` (after saying why) when the folder is absent, so that a user's fresh clone skips these
/// tests; under CI (`CI=true`) an absent folder is a failure instead.
pub fn scenes_dir() -> Option<PathBuf> {
    shared_dir("ARBOR_SCENES", "scenes")
}

/// The folder of shared benchmark meshes: `$ARBOR_MESHES`, or `../shared/meshes` beside the checkout.
pub fn meshes_dir() -> Option<PathBuf> {
    shared_dir("ARBOR_MESHES", "meshes")
}

fn shared_dir(var: &str, name: &str) -> Option<PathBuf> {
    let dir = match std::env::var_os(var) {
        Some(d) => PathBuf::from(d),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared").join(name),
    };
    if dir.is_dir() {
        return Some(dir);
    }
    let msg = format!("shared {name} folder {} not found (set {var})", dir.display());
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        panic!("{msg}: required under CI");
    }
    say_not_checked(var, &msg);
    None
}

/// Tells the user, once per test program and past the test harness's capture (which swallows `eprintln!`
/// of a passing test), that the tests which need the shared folder checked nothing.
fn say_not_checked(var: &str, msg: &str) {
    use std::io::Write;
    static SAID: std::sync::Once = std::sync::Once::new();
    SAID.call_once(|| {
        // The test program's name without the hash cargo appends (`reference_scenes-0123abcd...`).
        let path = std::env::args().next().unwrap_or_default();
        let file = Path::new(&path).file_name().map(|f| f.to_string_lossy().into_owned()).unwrap_or_default();
        let program = file.rsplit_once('-').map_or(file.as_str(), |(name, _)| name);
        // Straight to the stream, not `eprintln!`: libtest captures only the print macros.
        let _ = writeln!(
            std::io::stderr().lock(),
            "\nNOT CHECKED ({program}): {msg}. The tests that need it pass without checking anything; \
             put the shared folder beside the checkout or point {var} at it (CI=true makes its absence fail).\n"
        );
    });
}

/// Every file with extension `ext` below `dir`, sorted (none when `dir` cannot be read).
pub fn scene_files(dir: &Path, ext: &str) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let p = entry.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == ext) {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// The mesh files a scene names that are not there (the shared snapshot lacks files of 4 MiB or more).
pub fn missing_mesh_files(desc: &SceneDesc) -> Vec<PathBuf> {
    desc.objects
        .iter()
        .filter_map(|o| match &o.shape {
            ShapeDesc::Mesh { source: MeshSource::File(p), .. } if !p.is_file() => Some(p.clone()),
            _ => None,
        })
        .collect()
}

/// The image files a METU XML scene names (`Textures/Images/Image`, `EnvMapName`) that are not there,
/// relative to the scene's folder.
pub fn missing_image_files(scene: &Path) -> Vec<PathBuf> {
    let Ok(text) = std::fs::read_to_string(scene) else { return Vec::new() };
    let Ok(doc) = roxmltree::Document::parse(&text) else { return Vec::new() };
    let dir = scene.parent().unwrap_or(Path::new("."));
    doc.descendants()
        .filter(|n| n.has_tag_name("Image") || n.has_tag_name("EnvMapName"))
        .filter_map(|n| n.text().map(str::trim).filter(|t| !t.is_empty()))
        .map(|t| dir.join(t))
        .filter(|p| !p.is_file())
        .collect()
}
