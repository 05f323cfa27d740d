//! Integrators: what colour a camera ray brings back.

pub mod debug;
pub mod offset;
mod whitted;

pub use debug::{DebugIntegrator, DebugView};
pub use whitted::Whitted;
