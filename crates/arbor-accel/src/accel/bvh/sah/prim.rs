//! The SAH builder's primitive and boxes as SIMD lanes: a primitive in 32 bytes ([`SahPrim`]), a box
//! being grown ([`BoxAcc`]), and a node's bounds with its centroids' bounds ([`Boxes`]).

use crate::math::Aabb;
use glam::Vec4;

/// One primitive as the SAH builder sees it, in 32 bytes: its bounds as two SIMD vectors (aligned
/// loads, one `minps`/`maxps` per union on x86_64). Their fourth lanes carry the low and the high 16
/// bits of the primitive's index as small whole numbers: exact in `f32`, harmless in any arithmetic
/// the builder does on whole vectors, and ignored by it.
#[derive(Debug, Clone, Copy)]
pub(super) struct SahPrim {
    min: Vec4,
    max: Vec4,
}

impl SahPrim {
    #[inline(always)]
    pub(super) fn new(bounds: &Aabb, index: u32) -> SahPrim {
        SahPrim { min: bounds.min.extend((index & 0xffff) as f32), max: bounds.max.extend((index >> 16) as f32) }
    }
    #[inline(always)]
    pub(super) fn index(&self) -> u32 {
        self.min.w as u32 | (self.max.w as u32) << 16
    }
    /// The point the builder bins and splits by: the centre of the bounds, halved before adding so
    /// that boxes near the float range do not overflow (finite for finite bounds).
    #[inline(always)]
    pub(super) fn centroid(&self) -> Vec4 {
        self.min * 0.5 + self.max * 0.5
    }
    /// [`SahPrim::centroid`] on axis `A` (the same operations, so the same value).
    #[inline(always)]
    pub(super) fn centroid_on<const A: usize>(&self) -> f32 {
        0.5 * self.min[A] + 0.5 * self.max[A]
    }
}

/// A box being grown, in SIMD lanes. The builder's boxes are all finite, so the results are exactly
/// `Aabb::union`'s; the fourth lanes are ignored.
#[derive(Debug, Clone, Copy)]
pub(super) struct BoxAcc {
    min: Vec4,
    max: Vec4,
}

impl BoxAcc {
    pub(super) const EMPTY: BoxAcc = BoxAcc { min: Vec4::INFINITY, max: Vec4::NEG_INFINITY };

    #[inline(always)]
    pub(super) fn add_prim(self, p: &SahPrim) -> BoxAcc {
        BoxAcc { min: self.min.min(p.min), max: self.max.max(p.max) }
    }
    #[inline(always)]
    pub(super) fn add_point(self, p: Vec4) -> BoxAcc {
        BoxAcc { min: self.min.min(p), max: self.max.max(p) }
    }
    #[inline(always)]
    pub(super) fn union(self, o: BoxAcc) -> BoxAcc {
        BoxAcc { min: self.min.min(o.min), max: self.max.max(o.max) }
    }
    #[inline(always)]
    pub(super) fn aabb(self) -> Aabb {
        Aabb { min: self.min.truncate(), max: self.max.truncate() }
    }
    /// Surface area in double precision (`Aabb::area_f64`) of a box that is not empty.
    #[inline(always)]
    pub(super) fn area(self) -> f64 {
        let e = self.max.truncate().as_dvec3() - self.min.truncate().as_dvec3();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }
}

/// What a node knows about its primitives before it is split: their bounds and their centroids'
/// bounds (from the parent's binning and partition, or the setup pass for the root).
#[derive(Debug, Clone, Copy)]
pub(super) struct Boxes {
    pub(super) bounds: BoxAcc,
    pub(super) centroids: BoxAcc,
}

impl Boxes {
    pub(super) const EMPTY: Boxes = Boxes { bounds: BoxAcc::EMPTY, centroids: BoxAcc::EMPTY };

    #[inline(always)]
    pub(super) fn add(&mut self, p: &SahPrim) {
        self.bounds = self.bounds.add_prim(p);
        self.centroids = self.centroids.add_point(p.centroid());
    }
    #[inline]
    pub(super) fn union(self, o: Boxes) -> Boxes {
        Boxes { bounds: self.bounds.union(o.bounds), centroids: self.centroids.union(o.centroids) }
    }
    #[inline]
    pub(super) fn of(prims: &[SahPrim]) -> Boxes {
        let mut b = Boxes::EMPTY;
        for p in prims {
            b.add(p);
        }
        b
    }
}
