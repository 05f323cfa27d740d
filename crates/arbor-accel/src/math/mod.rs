//! Vector types (glam, single precision), rays, boxes and affine transforms.

mod aabb;
mod ray;
mod transform;

pub use aabb::Aabb;
pub use glam::{Mat3, Mat4, Vec2, Vec3};
pub use ray::Ray;
pub use transform::Transform;
