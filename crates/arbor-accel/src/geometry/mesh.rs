//! Indexed triangle meshes stored as flat arrays, as loaders produce them and the scene consumes them.

use crate::math::{Aabb, Transform, Vec2, Vec3};

/// An indexed triangle mesh. Indices are 0-based into `positions` (and `normals`, `uvs` when present).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriangleMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Triangles, counter-clockwise around the outward normal.
    pub indices: Vec<[u32; 3]>,
    /// Per-vertex normals, when the file gives them (or [`TriangleMesh::compute_vertex_normals`] made them).
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates, when the file gives them.
    pub uvs: Option<Vec<Vec2>>,
}

/// What [`TriangleMesh::check`] found wrong in a mesh that can still be rendered.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct MeshReport {
    /// Triangles with zero area (two equal vertices, or collinear ones); they are never hit.
    pub degenerate: usize,
}

impl TriangleMesh {
    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.indices.len()
    }
    /// True when the mesh has no triangle.
    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }
    /// The three corners of triangle `i`.
    #[inline]
    pub fn triangle(&self, i: usize) -> [Vec3; 3] {
        let [a, b, c] = self.indices[i];
        [self.positions[a as usize], self.positions[b as usize], self.positions[c as usize]]
    }
    /// Bounds of the referenced vertices.
    pub fn bounds(&self) -> Aabb {
        Aabb::from_points(self.positions.iter().copied())
    }
    /// Counts degenerate triangles. Index bounds and finite coordinates are the loaders' job (they know
    /// the line), so here they are only asserted in debug builds.
    pub fn check(&self) -> MeshReport {
        let n = self.positions.len() as u32;
        debug_assert!(self.indices.iter().all(|t| t.iter().all(|&i| i < n)));
        let degenerate = (0..self.len())
            .filter(|&i| {
                let [a, b, c] = self.triangle(i);
                (b - a).cross(c - a).length_squared() == 0.0
            })
            .count();
        MeshReport { degenerate }
    }
    /// Smooth vertex normals: at each vertex, the sum of the adjacent faces' normals weighted by their
    /// area (the unnormalised cross product), normalised. This is the course's "average of the adjacent
    /// face normals"; area weighting keeps slivers from tilting the result.
    pub fn compute_vertex_normals(&mut self) {
        let mut acc = vec![Vec3::ZERO; self.positions.len()];
        for i in 0..self.len() {
            let [a, b, c] = self.triangle(i);
            let n = (b - a).cross(c - a);
            for &v in &self.indices[i] {
                acc[v as usize] += n;
            }
        }
        for n in &mut acc {
            *n = n.normalize_or_zero();
        }
        self.normals = Some(acc);
    }
    /// The mesh with positions and normals taken through `t`. A mirroring transform also reverses the
    /// winding, so that counter-clockwise still means outward.
    pub fn transformed(&self, t: &Transform) -> TriangleMesh {
        if t.is_identity() {
            return self.clone();
        }
        let nm = t.normal_matrix();
        let mut out = TriangleMesh {
            positions: self.positions.iter().map(|&p| t.point(p)).collect(),
            indices: self.indices.clone(),
            normals: self.normals.as_ref().map(|ns| ns.iter().map(|&n| (nm * n).normalize_or_zero()).collect()),
            uvs: self.uvs.clone(),
        };
        if t.flips_handedness() {
            for tri in &mut out.indices {
                tri.swap(1, 2);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> TriangleMesh {
        TriangleMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
            indices: vec![[0, 1, 2], [0, 2, 3]],
            ..Default::default()
        }
    }

    #[test]
    fn mesh_vertex_normals_of_flat_quad_point_up() {
        let mut m = quad();
        m.compute_vertex_normals();
        assert!(m.normals.unwrap().iter().all(|n| n.abs_diff_eq(Vec3::Z, 1e-6)));
    }

    #[test]
    fn mesh_mirror_transform_keeps_outward_winding() {
        let m = quad().transformed(&Transform::scale(Vec3::new(-1.0, 1.0, 1.0)).unwrap());
        let [a, b, c] = m.triangle(0);
        assert!((b - a).cross(c - a).z > 0.0);
    }

    #[test]
    fn mesh_counts_degenerate_triangles() {
        let mut m = quad();
        m.indices.push([1, 1, 2]);
        assert_eq!(m.check().degenerate, 1);
    }
}
