//! Exact acceleration structures for ray tracing triangle meshes: brute force, octree, kd-tree (SAH),
//! BVH by median split, binned-SAH BVH and bottom-up agglomerative BVH, behind one interface.
//!
//! Every structure returns exactly the closest hit brute force returns: the smallest `t` in
//! `(0, t_max)`, and among primitives hit at that same `t`, the one with the lowest index. Triangles are
//! intersected watertight (Woop, Benthin and Wald 2013), so rays never slip between two triangles that
//! share an edge.
//!
//! Start at [`accel::Structure`] (build one with an [`accel::AccelConfig`] over a
//! [`geometry::TriangleMesh`] made with [`geometry::TriangleMesh::from_arrays`]). The crate's README
//! follows.
//!
#![doc = include_str!("../README.md")]
#![deny(missing_docs)]

pub mod accel;
pub mod geometry;
pub mod math;
#[cfg(test)]
mod test_rng;
