//! Arbor: a Whitted ray tracer for triangle meshes, built around fast and exactly correct acceleration
//! structures.
//!
//! Data flows one way: scene file -> [`scene::SceneDesc`] (format-neutral, with source positions) ->
//! [`scene::Scene`] (world-space primitives + an acceleration structure) -> [`render`] (integrator per
//! pixel, tiles over rayon, exact sample sums in [`accum`]) -> [`film::Film`] -> image file ([`image_io`]).
//! On a farm, [`farm`] cuts a frame into tiles and sample ranges written as partial EXRs and merges them
//! back into the same bits.
#![warn(missing_docs)]

pub mod accum;
pub mod bench;
pub mod camera;
pub mod error;
pub mod farm;
pub mod film;
pub mod image_io;
pub mod input;
pub mod integrator;
pub mod light;
pub mod material;
pub mod math;
pub mod mesh_io;
pub mod render;
pub mod sampler;
pub mod scene;

pub use arbor_accel::{accel, geometry};
pub use error::{Error, Location, Result};
