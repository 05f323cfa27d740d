//! PLACEHOLDER (being written): exact triangle-box overlap by the separating axis test.
use crate::math::{Aabb, Vec3};

/// Whether triangle `(a, b, c)` has a point in box `b`. Conservative for now: bounds overlap.
pub fn triangle_overlaps_box(a: Vec3, b: Vec3, c: Vec3, bx: &Aabb) -> bool {
    Aabb::from_points([a, b, c]).overlaps(bx)
}
