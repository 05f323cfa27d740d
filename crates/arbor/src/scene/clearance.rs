//! How far a point is from the scene's geometry, from below: the clearance of a point light, which
//! bounds the irradiance it can give any surface (`I / d²`, for the Whitted ray-tree pruning of
//! [`crate::integrator`]).
//!
//! A still mesh's triangles are taken to the world one by one and measured exactly (Ericson's closest
//! point, [`crate::geometry::closest_point_on_triangle`]); an untransformed still sphere and every
//! still plane exactly too. Everything else is measured to its world bounds, which lie around it, so the
//! answer is never more than the true distance: a moving object to its swept box, a transformed sphere to
//! its box, a moving plane as touching. Cost: one pass over the triangles of every object, instances
//! counted once each, cut to the boxes after `work` triangles (a lower bound all the same).

use super::geometry::{SceneGeometry, Shape};
use crate::geometry::closest_point_on_triangle;
use crate::math::{Aabb, Vec3};

/// Distance from `q` to the box `b` (0 inside it).
fn box_distance(q: Vec3, b: &Aabb) -> f32 {
    (b.min - q).max(q - b.max).max(Vec3::ZERO).length()
}

impl SceneGeometry {
    /// A lower bound on the distance from `q` to any surface of the scene, measuring at most `work`
    /// triangles exactly (the rest by their objects' boxes); infinite for an empty scene.
    pub fn clearance(&self, q: Vec3, work: usize) -> f32 {
        let mut left = work;
        let mut best = f32::INFINITY;
        for o in &self.objects.objects {
            let to_box = box_distance(q, &o.bounds);
            // Nothing inside the box can be nearer than the best so far.
            if to_box >= best {
                continue;
            }
            let exact = match (&o.shape, o.motion) {
                (Shape::Mesh(m), None) if m.mesh.len() <= left => {
                    left -= m.mesh.len();
                    let world = |p: Vec3| o.transform.as_ref().map_or(p, |t| t.point(p));
                    (0..m.mesh.len())
                        .map(|i| {
                            let [a, b, c] = m.mesh.triangle(i).map(world);
                            (closest_point_on_triangle(q, a, b, c) - q).length()
                        })
                        .fold(f32::INFINITY, f32::min)
                }
                (Shape::Sphere(s), None) if s.transform.is_identity() => ((s.center - q).length() - s.radius).max(0.0),
                _ => to_box,
            };
            best = best.min(exact);
        }
        for p in &self.planes {
            let d = if p.motion.is_some() { 0.0 } else { (q - p.plane.point).dot(p.plane.normal).abs() };
            best = best.min(d);
        }
        best
    }
}
