//! (being written: temporary stand-in with the final API)
use crate::math::{Color, Vec3};
use std::path::Path;
/// Environment map.
pub struct EnvMap;
impl EnvMap {
    /// Loads a map.
    pub fn load(path: &Path) -> crate::Result<EnvMap> {
        Err(crate::Error::Invalid(format!("{}: environment maps not written yet", path.display())))
    }
    /// Looks up a direction.
    pub fn eval(&self, _dir: Vec3) -> Color {
        Color::ZERO
    }
}
