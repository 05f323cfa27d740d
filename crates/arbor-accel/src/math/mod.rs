//! Vector types (glam, single precision; `DVec3` for closest-point queries), rays, boxes and affine transforms.

mod aabb;
mod ray;
mod transform;

pub use aabb::Aabb;
pub use glam::{DVec3, Mat3, Mat4, Vec2, Vec3};
pub use ray::Ray;
pub use transform::Transform;
