//! Indexed triangle meshes stored as flat arrays, as loaders produce them and the scene consumes them.
//! [`TriangleMesh::from_arrays`] is the checked way in from plain arrays: indices out of range and
//! non-finite positions are a [`MeshError`], not a panic later in a build or a query.

use std::fmt;

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

/// Why [`TriangleMesh::from_arrays`] (or [`TriangleMesh::validate`]) refused a mesh.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum MeshError {
    /// A triangle names a vertex that does not exist.
    IndexOutOfRange {
        /// The triangle (its index in the triangle array).
        triangle: usize,
        /// Which of its three corners (0, 1 or 2).
        corner: usize,
        /// The vertex index it names.
        index: u32,
        /// How many vertices there are.
        vertices: usize,
    },
    /// A vertex has a NaN or infinite coordinate.
    NonFinitePosition {
        /// The vertex (its index in the position array).
        vertex: usize,
        /// Its coordinates.
        position: [f32; 3],
    },
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MeshError::IndexOutOfRange { triangle, corner, index, vertices } => write!(
                f,
                "triangle {triangle}: corner {corner} names vertex {index}, but there are only {vertices} vertices"
            ),
            MeshError::NonFinitePosition { vertex, position: [x, y, z] } => {
                write!(f, "vertex {vertex}: position ({x}, {y}, {z}) is not finite")
            }
        }
    }
}

impl std::error::Error for MeshError {}

impl TriangleMesh {
    /// A mesh from vertex positions and triangles given as three 0-based indices into `positions`,
    /// counter-clockwise around the outward normal. Without normals or texture coordinates.
    ///
    /// ```
    /// use arbor_accel::geometry::{MeshError, TriangleMesh};
    ///
    /// let positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    /// let mesh = TriangleMesh::from_arrays(positions.clone(), vec![[0, 1, 2]])?;
    /// assert_eq!(mesh.len(), 1);
    ///
    /// let err = TriangleMesh::from_arrays(positions, vec![[0, 1, 3]]).unwrap_err();
    /// assert!(matches!(err, MeshError::IndexOutOfRange { triangle: 0, corner: 2, index: 3, vertices: 3 }));
    /// assert_eq!(err.to_string(), "triangle 0: corner 2 names vertex 3, but there are only 3 vertices");
    /// # Ok::<(), MeshError>(())
    /// ```
    ///
    /// # Errors
    /// [`MeshError::IndexOutOfRange`] for the first index past the end of `positions`,
    /// [`MeshError::NonFinitePosition`] for the first position with a NaN or infinite coordinate.
    pub fn from_arrays(positions: Vec<[f32; 3]>, triangles: Vec<[u32; 3]>) -> Result<TriangleMesh, MeshError> {
        let mesh = TriangleMesh {
            positions: positions.into_iter().map(Vec3::from).collect(),
            indices: triangles,
            normals: None,
            uvs: None,
        };
        mesh.validate()?;
        Ok(mesh)
    }

    /// Checks that every index names a vertex and every position is finite (what
    /// [`TriangleMesh::from_arrays`] guarantees, for meshes whose fields were filled directly).
    pub fn validate(&self) -> Result<(), MeshError> {
        if let Some((vertex, p)) = self.positions.iter().enumerate().find(|(_, p)| !p.is_finite()) {
            return Err(MeshError::NonFinitePosition { vertex, position: p.to_array() });
        }
        let vertices = self.positions.len();
        for (triangle, t) in self.indices.iter().enumerate() {
            if let Some(corner) = t.iter().position(|&i| i as usize >= vertices) {
                return Err(MeshError::IndexOutOfRange { triangle, corner, index: t[corner], vertices });
            }
        }
        Ok(())
    }

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
    fn mesh_from_arrays_keeps_the_arrays() {
        let m = TriangleMesh::from_arrays(
            vec![[0.0; 3], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
            vec![[0, 1, 2], [0, 2, 3]],
        )
        .unwrap();
        assert_eq!(m, quad());
        let empty = TriangleMesh::from_arrays(Vec::new(), Vec::new()).unwrap();
        assert!(empty.is_empty() && empty.bounds().is_empty());
    }

    #[test]
    fn mesh_from_arrays_refuses_indices_out_of_range() {
        let square = || vec![[0.0; 3], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        let err = TriangleMesh::from_arrays(square(), vec![[0, 1, 2], [0, 4, u32::MAX]]).unwrap_err();
        assert_eq!(err, MeshError::IndexOutOfRange { triangle: 1, corner: 1, index: 4, vertices: 4 });
        assert_eq!(err.to_string(), "triangle 1: corner 1 names vertex 4, but there are only 4 vertices");
        let err = TriangleMesh::from_arrays(Vec::new(), vec![[0, 0, 0]]).unwrap_err();
        assert_eq!(err.to_string(), "triangle 0: corner 0 names vertex 0, but there are only 0 vertices");
    }

    #[test]
    fn mesh_from_arrays_refuses_non_finite_positions() {
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            let err = TriangleMesh::from_arrays(vec![[0.0; 3], [1.0, bad, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2]])
                .unwrap_err();
            assert!(
                matches!(err, MeshError::NonFinitePosition { vertex: 1, position: [x, _, z] } if x == 1.0 && z == 0.0)
            );
            assert_eq!(err.to_string(), format!("vertex 1: position (1, {bad}, 0) is not finite"));
        }
        let e: Box<dyn std::error::Error> = Box::new(MeshError::NonFinitePosition { vertex: 0, position: [0.0; 3] });
        assert!(e.to_string().starts_with("vertex 0"));
    }

    #[test]
    fn mesh_counts_degenerate_triangles() {
        let mut m = quad();
        m.indices.push([1, 1, 2]);
        assert_eq!(m.check().degenerate, 1);
    }
}
