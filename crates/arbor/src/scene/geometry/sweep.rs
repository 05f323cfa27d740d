//! The box test of [`super::SceneGeometry::intersect_many`]'s sweep: which rays of a batch may meet an
//! object's box before their closest hit so far, so that the object traces only those. The top level's
//! walk does this for one ray at a time with its node test; the sweep, which hands each object the
//! batch at once, does it across the batch, lane by lane.
//!
//! Invariant: the test turns away no ray that the top level's own test of the same box lets in (more
//! slack, the same handling of NaN), so the sweep gives every ray the hit of its own query. Costs: the
//! batch's origins and directions copied once into rows of one axis each, then a few instructions per
//! ray and object.

use crate::math::{Aabb, Ray};

/// The slack of [`BatchRays::may_meet`]: 16 times the structures' own (`arbor-accel`'s `BOX_SLACK`).
const CULL_SLACK: f32 = 1.0 / 4096.0;

/// A batch's ray origins and reciprocal directions, axis by axis, for [`BatchRays::may_meet`], and
/// that test's running bounds and verdicts, one per ray.
pub(super) struct BatchRays {
    origin: [Vec<f32>; 3],
    inv_dir: [Vec<f32>; 3],
    near: Vec<f32>,
    far: Vec<f32>,
    scale: Vec<f32>,
    keep: Vec<bool>,
}

impl BatchRays {
    /// The rows of `rays`, and room for their bounds.
    pub(super) fn new(rays: &[Ray]) -> Self {
        let axis = |a: usize, inv: bool| rays.iter().map(|r| if inv { r.inv_dir[a] } else { r.origin[a] }).collect();
        BatchRays {
            origin: [0, 1, 2].map(|a| axis(a, false)),
            inv_dir: [0, 1, 2].map(|a| axis(a, true)),
            near: vec![0.0; rays.len()],
            far: vec![0.0; rays.len()],
            scale: vec![0.0; rays.len()],
            keep: vec![false; rays.len()],
        }
    }

    /// The rays that may meet what box `b` holds before their `limit`, by index into `which`: the top
    /// level's conservative slab test (`arbor-accel`'s `bvh/traverse.rs` argues it: the exit enlarged by
    /// a slack times the slab distances, which bounds a hit's rounding), with more slack than the top
    /// level gives the same box, so that it turns away no ray the top level would let in. As there,
    /// the planes a ray enters and leaves by are chosen by the sign of its direction, and a distance
    /// that is NaN (a ray along a slab's plane, `0 * inf`) does not count against the ray: each
    /// comparison keeps what it had. Written lane by lane without a branch, so that it runs across
    /// SIMD lanes: a few instructions per ray.
    // `!(near > far + slack)`, not `near <= far + slack`: a NaN keeps the ray.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    pub(super) fn may_meet(&mut self, b: &Aabb, limit: &[f32], which: &mut Vec<u32>) {
        let n = limit.len();
        let (near, far, scale) = (&mut self.near[..n], &mut self.far[..n], &mut self.scale[..n]);
        near.fill(0.0);
        far.copy_from_slice(limit);
        scale.fill(0.0);
        for a in 0..3 {
            let (o, inv) = (&self.origin[a][..n], &self.inv_dir[a][..n]);
            let (lo, hi) = (b.min[a], b.max[a]);
            for j in 0..n {
                let (enter, exit) = if inv[j].is_sign_negative() { (hi, lo) } else { (lo, hi) };
                let (t_in, t_out) = ((enter - o[j]) * inv[j], (exit - o[j]) * inv[j]);
                near[j] = if t_in > near[j] { t_in } else { near[j] };
                far[j] = if t_out < far[j] { t_out } else { far[j] };
                let size = if t_in.abs() > t_out.abs() { t_in.abs() } else { t_out.abs() };
                scale[j] = if size > scale[j] { size } else { scale[j] };
            }
        }
        // The verdicts in a pass of their own, which runs across lanes, then the indices.
        let keep = &mut self.keep[..n];
        for j in 0..n {
            keep[j] = !(near[j] > far[j] + scale[j] * CULL_SLACK);
        }
        which.clear();
        which.extend((0..n as u32).filter(|&j| keep[j as usize]));
    }
}
