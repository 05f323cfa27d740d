//! What the geometry's structures look like, for `arbor info`, the render summary, benchmarks and the
//! boxes debug view: statistics of the top level and every mesh's structure together, and the boxes of
//! their nodes at one depth. Both count depth the same way: within each structure, from its own root
//! (depth 0), so the deepest level the boxes view draws is the statistics' `max_depth`.

use std::collections::HashMap;

use super::{world_box, MeshShape, SceneGeometry, Shape};
use crate::accel::AccelStats;
use crate::math::Aabb;

impl SceneGeometry {
    /// The world-space boxes of the nodes at `depth` of every structure, for the boxes debug view: the
    /// top level's (over the objects) and each mesh object's own, `depth` counted from each one's root
    /// as [`SceneGeometry::accel_stats`] counts it. A mesh shared by several objects is walked once
    /// (a BVH's walk builds its binary tree again: [`crate::accel::Accel::boxes_at_depth`]).
    pub fn boxes_at_depth(&self, depth: usize) -> Vec<Aabb> {
        let mut out = self.top.boxes_at_depth(&self.objects, depth);
        let mut walked: HashMap<*const MeshShape, Vec<Aabb>> = HashMap::new();
        for o in &self.objects.objects {
            if let Shape::Mesh(m) = &o.shape {
                let boxes =
                    walked.entry(std::sync::Arc::as_ptr(m)).or_insert_with(|| m.accel.boxes_at_depth(&m.mesh, depth));
                out.extend(boxes.iter().map(|b| world_box(b, o.transform.as_ref())));
            }
        }
        out
    }

    /// Statistics of the structures together: the top level plus every distinct mesh's structure.
    /// Counts and bytes are summed; the build time is the wall time of the whole build
    /// ([`super::SceneCounts::build`]); depths are counted within each structure from its own root (the
    /// deepest leaf of any, the mean over all their leaves), as the boxes view counts them
    /// ([`SceneGeometry::boxes_at_depth`]); the SAH cost is the top level's plus each mesh's weighted
    /// by the share of the scene's area its object covers (an estimate).
    pub fn accel_stats(&self) -> AccelStats {
        let top = self.top.stats();
        let mut s = AccelStats { primitives: 0, build_time: self.counts.build, ..top.clone() };
        let (mut leaf_prims, mut depth_sum, mut refs) = (0.0, top.mean_depth * top.leaves as f64, 0.0);
        let scene_area = self.bounds().area().max(f32::MIN_POSITIVE) as f64;
        for m in &self.meshes {
            let ms = m.accel.stats();
            s.primitives += ms.primitives;
            s.nodes += ms.nodes;
            s.leaves += ms.leaves;
            s.bytes += ms.bytes;
            s.max_depth = s.max_depth.max(ms.max_depth);
            leaf_prims += ms.mean_leaf_prims * ms.leaves as f64;
            depth_sum += ms.mean_depth * ms.leaves as f64;
            refs += ms.refs_per_prim * ms.primitives as f64;
            s.sah_cost += ms.sah_cost * (m.accel.bounds().area() as f64 / scene_area).min(1.0);
        }
        s.primitives += self.counts.spheres;
        refs += self.counts.spheres as f64;
        let mesh_leaves = (s.leaves - top.leaves) as f64;
        if mesh_leaves > 0.0 {
            s.mean_leaf_prims = leaf_prims / mesh_leaves;
        }
        if s.leaves > 0 {
            s.mean_depth = depth_sum / s.leaves as f64;
        }
        s.refs_per_prim = if s.primitives > 0 { refs / s.primitives as f64 } else { 0.0 };
        s
    }
}
