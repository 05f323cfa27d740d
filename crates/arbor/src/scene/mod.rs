//! Scenes: the readers of each file format produce one [`SceneDesc`] (plain data with source
//! positions); the build step ([`Scene::build`], in `build.rs`) loads its assets and turns it into a
//! runtime [`Scene`]: geometry under acceleration structures (`geometry.rs`), materials, lights, cameras
//! and the settings shading needs (`runtime.rs`). Nothing reads the description after the build.
//!
//! The METU XML and JSON forms share one reader: both are first turned into the same element tree
//! ([`tree`]), and one interpreter ([`metu`]) reads the scene from that tree.

mod build;
pub mod desc;
mod geometry;
mod json;
mod limits;
mod metu;
mod nyu_json;
mod runtime;
mod tree;
mod xml;

use std::path::Path;

pub use build::{build_camera, build_geometry};
pub use desc::*;
pub use geometry::{MeshShape, SceneCounts, SceneGeometry, SceneObject, SceneObjects, Shape, SWEEP_OBJECTS};
pub use limits::{check_limits, SceneLimits};
pub use runtime::{RayOffset, Scene, Surface};

use crate::{Error, Location, Result};

/// Reads a scene file of any supported format: `.xml` (METU), `.json` (METU 2025 form, or the NYU
/// `scene.json` form, told apart by their top-level keys).
pub fn load_desc(path: &Path) -> Result<SceneDesc> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let text = String::from_utf8(bytes)
        .map_err(|e| Error::input(Location::byte(path, e.utf8_error().valid_up_to() as u64), "not UTF-8 text"))?;
    parse_desc(&text, path)
}

/// Reads a scene from `text` as if it were the file `path` (whose extension picks the format and whose
/// folder anchors relative mesh paths).
pub fn parse_desc(text: &str, path: &Path) -> Result<SceneDesc> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    match ext.as_str() {
        "xml" => metu::read(&xml::parse(text, path)?, path, metu::Form::Xml),
        "json" => {
            if nyu_json::looks_like_nyu(text) {
                nyu_json::parse(text, path)
            } else {
                metu::read(&json::parse(text, path)?, path, metu::Form::Json)
            }
        }
        _ => Err(Error::input(Location::file(path), format!("unknown scene format '.{ext}' (expected .xml or .json)"))),
    }
}
