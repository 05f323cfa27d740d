//! What a query does at a leaf: a mesh's leaves are blocks of four triangles tested at once
//! ([`MeshLeaves`]), other primitives are asked one by one ([`PrimLeaves`]). The traversal is compiled
//! once per kind (`dispatch.rs`), so the mesh loop carries no call into other primitives' code.
//!
//! Leaves ask for hits up to the float above the best `t` and keep ties by lowest primitive index
//! ([`ClosestHit`]), so a leaf block's four-lane test gives brute force's hits bit for bit.

use super::kernel::Lanes;
use super::{LeafBlock, Ref};
use crate::accel::closest::ClosestHit;
use crate::accel::{Hit, PrimHit, Primitives, TraversalCounts};
use crate::geometry::{intersect_triangles4, RayFrame};
use crate::math::Ray;

/// The leaves of a wide tree, as a query sees them.
pub(super) trait Leaves {
    /// Where leaf `r`'s data starts (its first block, or its primitive indices), to prefetch it.
    fn address(&self, r: Ref) -> *const i8;
    /// Offers leaf `r`'s hits below `best.t_query()` to `best`.
    fn closest<const COUNT: bool>(&self, r: Ref, q: &mut LeafRay, best: &mut ClosestHit, counts: &mut TraversalCounts);
    /// Whether leaf `r` has a hit in `(0, t_max)`.
    fn any(&self, r: Ref, q: &mut LeafRay, t_max: f32) -> bool;
}

/// The ray as leaves see it: the triangle test's part of it is computed at the first leaf (many rays,
/// such as a primary ray past the mesh, never reach one), from the major axis the box test chose.
pub(super) struct LeafRay<'a> {
    pub(super) ray: &'a Ray,
    major: usize,
    frame: Option<RayFrame>,
}

impl<'a> LeafRay<'a> {
    /// `ray`, whose major axis is `major`, before any leaf.
    #[inline(always)]
    pub(super) fn new(ray: &'a Ray, major: usize) -> Self {
        LeafRay { ray, major, frame: None }
    }

    #[inline(always)]
    fn frame(&mut self) -> &RayFrame {
        let (ray, major) = (self.ray, self.major);
        self.frame.get_or_insert_with(|| {
            debug_assert_eq!(major, crate::geometry::major_axis(ray.dir));
            RayFrame::with_major(ray, major)
        })
    }
}

/// `ray` prepared for a traversal: its lanes for the node tests and its view for the leaves.
#[inline(always)]
pub(super) fn prepare(ray: &Ray) -> (Lanes, LeafRay<'_>) {
    let lanes = Lanes::new(ray);
    let major = lanes.major;
    (lanes, LeafRay::new(ray, major))
}

/// The leaves of a triangle mesh: blocks of four triangles in leaf order.
pub(super) struct MeshLeaves<'a> {
    pub(super) blocks: &'a [LeafBlock],
}

impl Leaves for MeshLeaves<'_> {
    #[inline(always)]
    fn address(&self, r: Ref) -> *const i8 {
        self.blocks.as_ptr().wrapping_add(r.child as usize).cast()
    }

    #[inline(always)]
    fn closest<const COUNT: bool>(&self, r: Ref, q: &mut LeafRay, best: &mut ClosestHit, counts: &mut TraversalCounts) {
        if COUNT {
            counts.prims += r.count;
        }
        let frame = q.frame();
        for (block, lanes) in leaf_blocks(self.blocks, r) {
            let h = intersect_triangles4(frame, &block.tris, lanes, best.t_query());
            let mut m = h.mask;
            while m != 0 {
                let l = m.trailing_zeros() as usize;
                m &= m - 1;
                best.offer(Hit::new(block.prim[l], PrimHit::new(h.t[l], h.b1[l], h.b2[l])));
            }
        }
    }

    #[inline(always)]
    fn any(&self, r: Ref, q: &mut LeafRay, t_max: f32) -> bool {
        let frame = q.frame();
        leaf_blocks(self.blocks, r)
            .any(|(block, lanes)| intersect_triangles4(frame, &block.tris, lanes, t_max).mask != 0)
    }
}

/// The leaves of other primitives: ranges of primitive indices, each asked through [`Primitives`].
pub(super) struct PrimLeaves<'a, P: ?Sized> {
    pub(super) indices: &'a [u32],
    pub(super) prims: &'a P,
}

impl<P: Primitives + ?Sized> Leaves for PrimLeaves<'_, P> {
    #[inline(always)]
    fn address(&self, r: Ref) -> *const i8 {
        self.indices.as_ptr().wrapping_add(r.child as usize).cast()
    }

    #[inline(always)]
    fn closest<const COUNT: bool>(&self, r: Ref, q: &mut LeafRay, best: &mut ClosestHit, counts: &mut TraversalCounts) {
        let (first, ray) = (r.child as usize, q.ray);
        for &prim in &self.indices[first..first + r.count as usize] {
            let h = if COUNT {
                self.prims.intersect_counted(prim as usize, ray, best.t_query(), counts)
            } else {
                self.prims.intersect(prim as usize, ray, best.t_query())
            };
            if let Some(h) = h {
                best.offer(Hit::new(prim, h));
            }
        }
    }

    #[inline(always)]
    fn any(&self, r: Ref, q: &mut LeafRay, t_max: f32) -> bool {
        let first = r.child as usize;
        self.indices[first..first + r.count as usize].iter().any(|&p| self.prims.occludes(p as usize, q.ray, t_max))
    }
}

/// The blocks of leaf `leaf` with the lanes to test in each (all four but in the last block).
#[inline(always)]
pub(super) fn leaf_blocks(blocks: &[LeafBlock], leaf: Ref) -> impl Iterator<Item = (&LeafBlock, u32)> {
    let first = leaf.child as usize;
    let n = leaf.count as usize;
    blocks[first..first + n.div_ceil(4)].iter().enumerate().map(move |(k, b)| {
        let left = n - 4 * k;
        (b, if left >= 4 { 0b1111 } else { (1 << left) - 1 })
    })
}
