//! Axis-aligned bounding boxes. (The ray-box test lives with the traversal that needs its exact
//! conservativeness: `accel::bvh`.)

use super::Vec3;

/// An axis-aligned box. The empty box has `min = +inf`, `max = -inf`, so that `union` needs no branch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// Lower corner.
    pub min: Vec3,
    /// Upper corner.
    pub max: Vec3,
}

impl Default for Aabb {
    fn default() -> Self {
        Aabb::EMPTY
    }
}

impl Aabb {
    /// The box that contains nothing.
    pub const EMPTY: Aabb = Aabb { min: Vec3::INFINITY, max: Vec3::NEG_INFINITY };

    /// The box spanning two corners.
    #[inline]
    pub fn new(min: Vec3, max: Vec3) -> Self {
        Aabb { min, max }
    }
    /// The box of one point.
    #[inline]
    pub fn point(p: Vec3) -> Self {
        Aabb { min: p, max: p }
    }
    /// The box of some points.
    pub fn from_points(points: impl IntoIterator<Item = Vec3>) -> Self {
        points.into_iter().fold(Aabb::EMPTY, |b, p| b.grow(p))
    }
    /// True when the box holds no point.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }
    /// This box grown to include `p`.
    #[inline]
    pub fn grow(self, p: Vec3) -> Self {
        Aabb { min: self.min.min(p), max: self.max.max(p) }
    }
    /// The smallest box holding both.
    #[inline]
    pub fn union(self, o: Aabb) -> Self {
        Aabb { min: self.min.min(o.min), max: self.max.max(o.max) }
    }
    /// Size along each axis.
    #[inline]
    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }
    /// Centre point.
    #[inline]
    pub fn center(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }
    /// Surface area (0 for an empty box).
    #[inline]
    pub fn area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let e = self.extent();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }
    /// Surface area in double precision, so that boxes near the float range do not overflow to infinity
    /// (0 for an empty box).
    #[inline]
    pub fn area_f64(&self) -> f64 {
        if self.is_empty() {
            return 0.0;
        }
        let e = self.max.as_dvec3() - self.min.as_dvec3();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }
    /// Index of the longest axis.
    #[inline]
    pub fn longest_axis(&self) -> usize {
        let e = self.extent();
        if e.x >= e.y && e.x >= e.z {
            0
        } else if e.y >= e.z {
            1
        } else {
            2
        }
    }
    /// The box common to both (empty when they do not meet).
    #[inline]
    pub fn intersection(self, o: Aabb) -> Self {
        Aabb { min: self.min.max(o.min), max: self.max.min(o.max) }
    }
    /// True when the boxes share at least a point (touching counts).
    #[inline]
    pub fn overlaps(&self, o: &Aabb) -> bool {
        self.min.cmple(o.max).all() && o.min.cmple(self.max).all()
    }
    /// True when `o` lies inside this box (boundaries included).
    #[inline]
    pub fn contains(&self, o: &Aabb) -> bool {
        o.is_empty() || (self.min.cmple(o.min).all() && self.max.cmpge(o.max).all())
    }
}
