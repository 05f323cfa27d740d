//! PLACEHOLDER (being written): triangle clipped to a box (Sutherland-Hodgman), for perfect splits.
use crate::math::{Aabb, Vec3};

/// Bounds of the part of triangle `(a, b, c)` inside `bx`. Conservative for now: bounds cut by the box.
pub fn clip_triangle_bounds(a: Vec3, b: Vec3, c: Vec3, bx: &Aabb) -> Aabb {
    Aabb::from_points([a, b, c]).intersection(*bx)
}
