//! Runs the Python test suite (`tests/python`, pytest) against the extension this `cargo test` built,
//! so that README's test command covers the Python module too.
//!
//! Cargo builds the library as a cdylib beside the test binaries (`target/<profile>/deps/libarbor_rays.so`:
//! `cargo test` does not copy it up to `target/<profile>`, where an older build's may lie); that file, renamed to what Python imports (`_native.abi3.so`), goes into a temporary copy of the
//! Python package (`python/arbor_rays`), which pytest imports through `PYTHONPATH`. Built by cargo the
//! extension links libpython (PyO3's `extension-module` feature is maturin's only), which the
//! interpreter that loads it has already loaded.
//!
//! The interpreter is `ARBOR_PYTHON` (default `python3`) and needs numpy and pytest (trimesh too for
//! the adapter tests; `.ci/run` makes such a virtual environment). Without them the test passes
//! saying NOT CHECKED, and fails under `CI=true`. The `arbor` binary of the same build, when there
//! is one, is handed over as `ARBOR_BIN` for the test comparing `render` with the CLI's image.

use std::path::{Path, PathBuf};
use std::process::Command;

fn not_checked(why: &str) {
    if std::env::var("CI").as_deref() == Ok("true") {
        panic!("the Python tests cannot run under CI=true: {why}");
    }
    eprintln!("NOT CHECKED: the Python tests did not run: {why}");
}

/// The folder of this build's artifacts (`target/release`) and its `deps`, where the test binary and
/// the cdylib this test was built with lie.
fn artifacts() -> (PathBuf, PathBuf) {
    let exe = std::env::current_exe().expect("the test binary's path");
    let deps = exe.parent().expect("target/<profile>/deps/<test>").to_path_buf();
    let dir = deps.parent().expect("target/<profile>/deps").to_path_buf();
    (dir, deps)
}

/// The cdylib's file name here, and the name Python imports it by.
fn extension_names() -> (&'static str, &'static str) {
    if cfg!(target_os = "windows") {
        ("arbor_rays.dll", "_native.pyd")
    } else if cfg!(target_os = "macos") {
        ("libarbor_rays.dylib", "_native.abi3.so")
    } else {
        ("libarbor_rays.so", "_native.abi3.so")
    }
}

#[test]
fn python_suite_passes_against_this_build() {
    let python = std::env::var("ARBOR_PYTHON").unwrap_or_else(|_| "python3".into());
    let probe = Command::new(&python).args(["-c", "import numpy, pytest"]).output();
    match probe {
        Ok(o) if o.status.success() => {}
        Ok(o) => {
            return not_checked(&format!(
                "{python} lacks numpy or pytest ({}); set ARBOR_PYTHON to one that has them",
                String::from_utf8_lossy(&o.stderr).lines().last().unwrap_or("")
            ))
        }
        Err(e) => return not_checked(&format!("cannot run {python}: {e}")),
    }
    let (dir, deps) = artifacts();
    let (built, imported) = extension_names();
    let lib = deps.join(built);
    assert!(lib.is_file(), "cargo built no extension at {}", lib.display());

    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let root = std::env::temp_dir().join(format!("arbor-py-test-{}", std::process::id()));
    let package = root.join("arbor_rays");
    std::fs::create_dir_all(&package).expect("a temporary folder");
    for entry in std::fs::read_dir(crate_dir.join("python/arbor_rays")).expect("the Python package") {
        let path = entry.expect("a package file").path();
        if path.is_file() {
            std::fs::copy(&path, package.join(path.file_name().expect("a file name"))).expect("copy");
        }
    }
    std::fs::copy(&lib, package.join(imported)).expect("copy the extension");

    let mut cmd = Command::new(&python);
    cmd.args(["-m", "pytest", "-q", "-p", "no:cacheprovider", "tests/python"])
        .current_dir(crate_dir)
        .env("PYTHONPATH", &root)
        .env("PYTHONDONTWRITEBYTECODE", "1");
    let arbor = dir.join(if cfg!(windows) { "arbor.exe" } else { "arbor" });
    if arbor.is_file() {
        cmd.env("ARBOR_BIN", &arbor);
    }
    let out = cmd.output().expect("run pytest");
    let _ = std::fs::remove_dir_all(&root);
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    eprintln!("{text}");
    assert!(out.status.success(), "the Python tests failed (pytest exit {:?})", out.status.code());
}
