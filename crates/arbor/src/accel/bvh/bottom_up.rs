//! PLACEHOLDER: bottom-up BVH parameters (being written).
use crate::accel::params::{unknown_key, Params};

/// Parameters of the bottom-up builders.
#[derive(Debug, Clone, Default)]
pub struct BottomUpParams {}

impl Params for BottomUpParams {
    const KEYS: &'static [(&'static str, &'static str)] = &[];
    fn set(&mut self, key: &str, _value: &str) -> Result<(), String> {
        Err(unknown_key("bvh-bottom-up", key, Self::KEYS))
    }
}
