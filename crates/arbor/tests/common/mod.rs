//! Helpers shared by the integration tests: where the shared real-world data lives.
#![allow(dead_code)]

use std::path::PathBuf;

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
    eprintln!("SKIPPED: {msg}");
    None
}
