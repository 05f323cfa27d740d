//! Arbor: a Whitted ray tracer for triangle meshes, built around fast and exactly correct acceleration
//! structures.
//!
//! Data flows one way, each step a layer that uses only the ones below it (docs/architecture.md):
//! scene file -> readers ([`scene::load_desc`]) -> [`scene::SceneDesc`] (plain data with source
//! positions) -> the build step ([`scene::Scene::build`]: loads meshes and environment maps, builds the
//! acceleration structures) -> [`scene::Scene`] (runtime types only: [`scene::SceneGeometry`] over
//! [`accel`], [`material::Material`], [`light::Light`], [`camera::Camera`]) -> [`integrator`] per pixel
//! -> [`render`] (tiles over rayon, exact sample sums in [`accum`]) -> [`film::Film`] -> image file
//! ([`image_io`]). Shading never reads the description. On a farm, [`farm`] cuts a frame into tiles and
//! sample ranges written as partial EXRs and merges them back into the same bits.
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
pub mod renderer;
pub mod sampler;
pub mod scene;
pub mod texture;
pub mod tonemap;

pub use arbor_accel::{accel, geometry};
pub use error::{Error, Location, Result};
