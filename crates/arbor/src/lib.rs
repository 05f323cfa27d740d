//! Arbor: a Whitted ray tracer for triangle meshes, built around fast and exactly correct acceleration
//! structures.
//!
//! Data flows one way: scene file -> [`scene::SceneDesc`] (format-neutral, with source positions) ->
//! [`scene::Scene`] (world-space primitives + an acceleration structure) -> [`render`] (integrator per
//! pixel, tiles over rayon) -> [`film::Film`] -> image file ([`image_io`]).
#![warn(missing_docs)]

pub mod accel;
pub mod accum;
pub mod bench;
pub mod camera;
pub mod error;
pub mod farm;
pub mod film;
pub mod geometry;
pub mod image_io;
pub mod integrator;
pub mod light;
pub mod material;
pub mod math;
pub mod mesh_io;
pub mod render;
pub mod sampler;
pub mod scene;

pub use error::{Error, Location, Result};
