//! (being written)
use super::SceneDesc;
pub fn looks_like_nyu(_text: &str) -> bool {
    false
}
pub fn parse(_text: &str, path: &std::path::Path) -> crate::Result<SceneDesc> {
    Err(crate::Error::Invalid(format!("{}: NYU reader not written yet", path.display())))
}
