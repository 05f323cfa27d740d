//! How a BVH was built, kept so that a mesh BVH whose binary tree was dropped (see `mod.rs`) can build
//! that tree again for the boxes debug view: the view's depths are the binary tree's, the ones
//! [`Accel::stats`](crate::accel::Accel::stats) reports and `arbor info` shows, while the 8-wide tree the
//! queries read has about a third as many levels. No build depends on the thread count, so the tree
//! built again is the one dropped. It costs one more build of the mesh, paid only by that view.

use super::{Binary, BottomUpParams, Bvh, BvhParams, MedianParams};
use crate::accel::Primitives;

/// A builder and its parameters.
#[derive(Debug, Clone)]
pub(crate) enum Recipe {
    Sah(BvhParams),
    Median(MedianParams),
    BottomUp(BottomUpParams),
}

impl Recipe {
    /// The structure's name ([`crate::accel::AccelKind::name`]).
    pub(super) fn kind(&self) -> &'static str {
        match self {
            Recipe::Sah(_) => "bvh-sah",
            Recipe::Median(_) => "bvh-median",
            Recipe::BottomUp(_) => "bvh-bottom-up",
        }
    }

    /// The same build over `prims`, keeping its binary tree.
    pub(super) fn build_kept<P: Primitives + ?Sized>(&self, prims: &P) -> Bvh {
        match self {
            Recipe::Sah(p) => Bvh::sah(prims, p, Binary::Keep),
            Recipe::Median(p) => Bvh::median(prims, p, Binary::Keep),
            Recipe::BottomUp(p) => Bvh::bottom_up(prims, p, Binary::Keep),
        }
    }
}
