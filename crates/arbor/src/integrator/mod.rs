//! Integrators: what colour a camera ray brings back.

mod whitted;

pub use whitted::Whitted;
