//! The readers: scene file text -> [`SceneDesc`], or an error at the file, line and column. `.xml` is the
//! METU course form, `.json` either its 2025 JSON form or the NYU `scene.json` (told apart by their
//! top-level keys).
//!
//! The METU XML and JSON forms share one reader: both are first turned into the same element tree
//! ([`tree`]), and one interpreter ([`metu`]) reads the scene from that tree.

mod json;
mod metu;
mod nyu_json;
mod tree;
mod xml;

use std::path::Path;

use crate::scene::desc::SceneDesc;
use crate::{Error, Location, Result};

/// Reads a scene file of any supported format: `.xml` (METU), `.json` (METU 2025 form, or the NYU
/// `scene.json` form, told apart by their top-level keys).
pub fn load_desc(path: &Path) -> Result<SceneDesc> {
    let bytes = crate::input::load_bytes(path)?;
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
