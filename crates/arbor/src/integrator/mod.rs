//! Integrators: what colour a camera ray brings back.

pub mod debug;
mod whitted;

pub use debug::{DebugIntegrator, DebugView};
pub use whitted::Whitted;
