//! Shapes and their ray intersection: triangle meshes (flat arrays), spheres, infinite planes.

mod closest_point;
#[doc(hidden)]
pub mod error_bound;
mod mesh;
mod plane;
mod sphere;
mod triangle;
mod triangle4;
mod triangle_box;
mod triangle_clip;

pub use closest_point::{closest_point_on_triangle, closest_point_on_triangle_f64};
pub use mesh::{MeshError, MeshReport, TriangleMesh};
pub use plane::Plane;
pub use sphere::Sphere;
pub use triangle::{intersect_triangle, TriHit};
// The ray frames and SIMD lanes of the traversal kernels: shared with the structures, not an API.
#[doc(hidden)]
pub use triangle::{intersect_triangle_in, major_axis, RayFrame};
#[doc(hidden)]
pub use triangle4::{intersect_triangles4, Tri4, Tri4Hits};
pub use triangle_box::triangle_overlaps_box;
pub use triangle_clip::clip_triangle_bounds;
