//! Mesh file readers: bytes -> [`TriangleMesh`] or an error located in the file.
use std::path::Path;

use crate::geometry::TriangleMesh;
use crate::Result;

/// Loads a mesh file, picking the reader by extension.
pub fn load_mesh(path: &Path) -> Result<TriangleMesh> {
    Err(crate::Error::Invalid(format!("{}: mesh loading not written yet", path.display())))
}
