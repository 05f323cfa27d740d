//! Shapes and their ray intersection: triangle meshes (flat arrays), spheres, infinite planes.

mod mesh;
mod plane;
mod sphere;
mod triangle;

pub use mesh::{MeshReport, TriangleMesh};
pub use plane::Plane;
pub use sphere::Sphere;
pub use triangle::{intersect_triangle, TriHit};
