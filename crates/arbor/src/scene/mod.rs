//! Scenes, in three layers (docs/architecture.md): the readers (`readers/`) turn each file format into
//! one [`SceneDesc`] (`desc.rs`: plain data with source positions; `limits.rs` bounds what it may ask
//! for); the build step ([`Scene::build`], `build.rs`) loads its assets and turns it into a runtime
//! [`Scene`]: geometry under acceleration structures (`geometry.rs`), materials, lights, cameras and
//! the settings shading needs (`runtime.rs`), and how far a point is from the geometry (`clearance.rs`). Nothing reads the description after the build. This file
//! only re-exports.

mod build;
mod clearance;
pub mod desc;
mod geometry;
mod limits;
mod readers;
mod runtime;

pub use build::{build_camera, build_geometry};
pub use desc::*;
pub use geometry::{
    MeshShape, SceneCounts, SceneGeometry, SceneObject, SceneObjects, ScenePlane, Shape, SWEEP_MEAN_TRIANGLES,
    SWEEP_OBJECTS,
};
pub use limits::{check_limits, SceneLimits};
pub use readers::{load_desc, parse_desc};
pub use runtime::{RayOffset, Scene, Surface};
