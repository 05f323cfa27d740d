//! (being written)
use super::{tree::Node, SceneDesc};
pub fn read(_root: &Node, path: &std::path::Path) -> crate::Result<SceneDesc> {
    Err(crate::Error::Invalid(format!("{}: METU reader not written yet", path.display())))
}
