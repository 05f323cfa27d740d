//! `arbor bench`: the acceleration structures over one scene, mesh or generated sphere.
//!
//! Two forms, one file each, both reading their flags from [`args`]:
//! - [`scene`]: every chosen structure traces the same primary and diffuse rays, generated from the
//!   default structure's hits; one row per structure (build statistics, Mrays/s, speedup over brute
//!   force, hits that differ from the default structure's: any is an error, exit 3).
//! - [`ray_dir`] (`--ray-dir DIR`): the rays the peers' harness dumped, traced over a mesh file and
//!   printed in the harness's own line format, to put Arbor beside Embree and obvhs on identical rays.
//!
//! This file only dispatches; neither form knows the other.

mod args;
mod ray_dir;
mod scene;

pub use args::BenchArgs;

use crate::Failure;

/// Runs `arbor bench`.
pub fn run(args: BenchArgs) -> Result<(), Failure> {
    match &args.ray_dir {
        Some(dir) => ray_dir::run(&args, dir),
        None => scene::run(&args),
    }
}
