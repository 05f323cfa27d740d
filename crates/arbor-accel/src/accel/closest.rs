//! The closest-hit bookkeeping every traversal shares (BVH, wide BVH, kd-tree, octree, brute force), so
//! that all of them keep the same hit: the smallest `t`, and among hits at that same `t`, the lowest
//! primitive index ([`Hit::beats`]).
//!
//! A structure meets primitives in its own order, not by index, so a hit at exactly the best `t` must
//! still be seen: primitives are asked for hits below [`ClosestHit::t_query`], the float just above the
//! best `t` (`(0, t_query)` holds exactly the `t <= best`), while nodes and cells are culled against
//! [`ClosestHit::t_far`], the best `t` itself (each structure's culling test keeps a node whose entry
//! equals it).

use super::Hit;
use crate::math::Ray;

/// True when no query can hit anything: an invalid ray (NaN or zero direction) or an empty
/// `(0, t_max)`. Every structure asks this before its traversal.
#[inline]
pub(crate) fn trivially_misses(ray: &Ray, t_max: f32) -> bool {
    !ray.is_valid() || t_max.is_nan() || t_max <= 0.0
}

/// The closest hit so far of one query in `(0, t_max)`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ClosestHit {
    hit: Option<Hit>,
    t_far: f32,
    t_query: f32,
}

impl ClosestHit {
    /// No hit yet, in `(0, t_max)`.
    #[inline(always)]
    pub(crate) fn new(t_max: f32) -> Self {
        ClosestHit { hit: None, t_far: t_max, t_query: t_max }
    }

    /// Keeps `hit` when it beats the best so far (smaller `t`, or equal `t` and lower index).
    #[inline(always)]
    pub(crate) fn offer(&mut self, hit: Hit) {
        if hit.beats(&self.hit) {
            self.t_far = hit.t;
            // Hits are in `(0, t_max)`, positive: the next float up is the next bit pattern, and
            // `(0, t_query)` is `(0, t]`.
            self.t_query = hit.t.next_up();
            self.hit = Some(hit);
        }
    }

    /// The best hit so far.
    #[inline(always)]
    pub(crate) fn hit(&self) -> Option<Hit> {
        self.hit
    }

    /// The best `t` so far, or `t_max`: nothing farther can be the closest hit.
    #[inline(always)]
    pub(crate) fn t_far(&self) -> f32 {
        self.t_far
    }

    /// The bound to ask primitives with: just above [`ClosestHit::t_far`] once there is a hit, so that
    /// a hit tying the best `t` is still returned and weighed by index.
    #[inline(always)]
    pub(crate) fn t_query(&self) -> f32 {
        self.t_query
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::PrimHit;

    fn hit(prim: u32, t: f32) -> Hit {
        Hit::new(prim, PrimHit::new(t, 0.25, 0.5))
    }

    #[test]
    fn closest_hit_keeps_the_smaller_t_then_the_lower_index() {
        let mut c = ClosestHit::new(10.0);
        assert_eq!((c.hit(), c.t_far().to_bits(), c.t_query().to_bits()), (None, 10f32.to_bits(), 10f32.to_bits()));
        c.offer(hit(5, 3.0));
        assert_eq!(c.hit(), Some(hit(5, 3.0)));
        assert_eq!(c.t_far().to_bits(), 3f32.to_bits());
        assert_eq!(c.t_query().to_bits(), 3f32.to_bits() + 1, "the float just above the best t");
        c.offer(hit(2, 3.0));
        assert_eq!(c.hit(), Some(hit(2, 3.0)), "a tie goes to the lower index");
        c.offer(hit(7, 3.0));
        assert_eq!(c.hit(), Some(hit(2, 3.0)), "a tie with a higher index is refused");
        c.offer(hit(9, 2.5));
        assert_eq!(c.hit(), Some(hit(9, 2.5)), "a smaller t wins whatever its index");
        c.offer(hit(0, 2.5f32.next_up()));
        assert_eq!(c.hit(), Some(hit(9, 2.5)), "a larger t loses whatever its index");
    }

    #[test]
    fn closest_hit_next_float_above_tiny_and_huge_hits() {
        let mut c = ClosestHit::new(f32::INFINITY);
        c.offer(hit(0, f32::MAX));
        assert_eq!(c.t_query(), f32::INFINITY);
        let tiny = f32::from_bits(1);
        c.offer(hit(1, tiny));
        assert_eq!(c.t_query().to_bits(), 2, "subnormal hits step by one bit pattern too");
    }
}
