//! Bounding volume hierarchy: a binary tree of axis-aligned boxes over primitive indices, stored as one
//! flat array of 32-byte nodes (pbrt's `LinearBVHNode`). Three builders write that array, and share
//! the build machinery (`build.rs`), the traversal (`wide/`, checked against the binary `traverse.rs`) and
//! the checks (`validate.rs`):
//! - [`Bvh::build_sah`] (`sah/`): top-down, binned surface area heuristic (Wald 2007, "On fast
//!   construction of SAH-based bounding volume hierarchies"; pbrt-v4's `BVHAggregate`);
//! - [`Bvh::build_median`] (`median.rs`): top-down, split at the median centroid on the longest axis;
//! - [`Bvh::build_bottom_up`] (`bottom_up/`): agglomerative, the exact greedy method for small inputs
//!   and PLOC (Meister and Bittner 2018) for any size.
//!
//! Layout: nodes are written depth first, so an inner node's first child is the next node and only the
//! second child's index is stored. Leaves hold a range of [`Bvh::prim_indices`], the primitive indices
//! reordered so that every leaf's primitives are contiguous.
//!
//! Over a triangle mesh the wide tree's leaves hold their own copies of the triangles and their
//! indices, so the build drops the binary tree and the index array once collapsed, keeping the root
//! box and the statistics taken before; the boxes debug view builds the binary tree again
//! (`recipe.rs`), so that its depths stay the ones the statistics count, and [`Accel::validate`] checks
//! the wide tree (`wide/check.rs`). Other primitives keep both: their leaves read the index array.
//!
//! Invariants of the binary tree (checked by [`Accel::validate`], which the factory runs in debug builds):
//! - every node's box encloses its children's boxes and its primitives' boxes;
//! - every primitive index appears exactly once in [`Bvh::prim_indices`]; the first `live` are reachable
//!   from the root through leaves whose ranges tile `0..live` in depth-first order, the rest are
//!   primitives with empty or non-finite bounds, which can never be hit and are left out of the tree so
//!   that they cannot poison node boxes;
//! - leaves hold at most [`LEAF_HARD_MAX`] primitives and the tree is at most [`MAX_DEPTH`] deep, so the
//!   fixed-size traversal stack cannot overflow.
//!
//! Cost: the SAH and median builds are O(n log n) (one binning or selection pass per level), with the
//! two halves of large nodes built in parallel; PLOC is O(n log n) in practice, the greedy method
//! O(n²) (see their modules). No result depends on the thread count. A query is O(log n) on
//! well-distributed scenes; while kept, the binary tree takes 32 bytes per node (about `2n / leaf size`
//! nodes) plus 4 bytes per primitive, on top of the wide tree.

mod bottom_up;
mod build;
mod median;
mod params;
mod recipe;
mod sah;
mod traverse;
mod validate;
mod wide;

use std::time::{Duration, Instant};

pub use bottom_up::{BottomUpMethod, BottomUpParams, MergeCost};
pub use params::{BvhParams, MedianParams};
use recipe::Recipe;
use wide::Kernel;
pub use wide::{Isa, Node8, Wide, MAX_ISA_VAR};

use super::nearest;
use super::stats::StatsTally;
use super::{Accel, AccelStats, Hit, Nearest, Primitives, TraversalCounts};
use crate::math::{Aabb, DVec3, Ray, Vec3};

/// Largest number of primitives in one leaf, whatever the parameters: a leaf of coincident centroids
/// above it is split in the middle of its index range.
pub const LEAF_HARD_MAX: usize = 64;

/// The node-test kernel the wide BVH's queries run on this processor, detected at run time: `avx512`
/// (8 lanes at once, the whole query compiled for AVX-512 F and VL), `avx2` (8 lanes at once, compiled
/// for AVX2), `sse` (two 4-lane halves) or `scalar`; [`MAX_ISA_VAR`] caps it.
pub fn query_kernel() -> &'static str {
    Kernel::detect().name()
}

/// Every node's depth (root at depth 0) is below this, which sizes the traversal stack. From depth 64
/// on, the SAH builder stops looking for SAH splits and halves index ranges, and the bottom-up builder
/// rebuilds subtrees that are still too deep with the median split; either adds at most 32 levels.
pub const MAX_DEPTH: usize = MAX_SAH_DEPTH + 33;

/// Depth after which SAH splits are no longer tried. Binned splits shrink the centroid extent by at
/// least one bin per level, so adversarial inputs (exponentially spaced centroids) could otherwise
/// produce trees hundreds of levels deep.
const MAX_SAH_DEPTH: usize = 64;

/// Most bins a binned SAH build uses.
pub const MAX_BINS: usize = 32;

/// One node of the flat array: pbrt-v4's `LinearBVHNode`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C)]
pub struct Node {
    /// Lower corner of the node's box.
    pub min: [f32; 3],
    /// Upper corner of the node's box.
    pub max: [f32; 3],
    /// Inner node: index of the second child (the first is the next node). Leaf: offset of its first
    /// primitive in [`Bvh::prim_indices`].
    pub offset: u32,
    /// Number of primitives of a leaf; 0 marks an inner node.
    pub count: u16,
    /// Split axis of an inner node (0, 1, 2); traversal visits the child on the ray's side first.
    pub axis: u8,
    pad: u8,
}

const _: () = assert!(std::mem::size_of::<Node>() == 32);

impl Node {
    /// A leaf over `count` primitives starting at `first` in the index array.
    pub fn leaf(bounds: Aabb, first: u32, count: u16) -> Self {
        debug_assert!(count > 0);
        Node { min: bounds.min.to_array(), max: bounds.max.to_array(), offset: first, count, axis: 0, pad: 0 }
    }
    /// An inner node split on `axis` whose second child is node `second`.
    pub fn inner(bounds: Aabb, second: u32, axis: u8) -> Self {
        Node { min: bounds.min.to_array(), max: bounds.max.to_array(), offset: second, count: 0, axis, pad: 0 }
    }
    /// The node's box.
    #[inline]
    pub fn bounds(&self) -> Aabb {
        Aabb::new(Vec3::from_array(self.min), Vec3::from_array(self.max))
    }
    /// True for a leaf.
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

/// Whether a BVH over a triangle mesh keeps its binary tree and index array after the collapse: its
/// queries read only the wide tree and its triangle blocks, so the public builders drop them; the
/// boxes view and tests that inspect the binary tree keep it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Binary {
    DropForMesh,
    Keep,
}

/// A bounding volume hierarchy over primitive indices.
#[derive(Debug, Clone)]
pub struct Bvh {
    /// Empty (with `prim_indices`) once dropped, see [`Binary`].
    nodes: Vec<Node>,
    prim_indices: Vec<u32>,
    live: usize,
    primitives: usize,
    bounds: Aabb,
    wide: Wide,
    /// The binary tree's statistics, taken before it was dropped (`bytes` and `build_time` are filled
    /// in when asked); `None` while the tree is kept, whose statistics are computed when asked.
    dropped_stats: Option<AccelStats>,
    recipe: Recipe,
    build_time: Duration,
}

impl Bvh {
    /// Builds a BVH over `prims` with binned SAH splits.
    pub fn build_sah<P: Primitives + ?Sized>(prims: &P, params: &BvhParams) -> Bvh {
        Bvh::sah(prims, params, Binary::DropForMesh)
    }

    pub(crate) fn sah<P: Primitives + ?Sized>(prims: &P, params: &BvhParams, binary: Binary) -> Bvh {
        let start = Instant::now();
        let recipe = Recipe::Sah(*params);
        let mut params = params.sanitized();
        if prims.triangle_mesh().is_none() {
            params.leaf_block = 1;
        }
        let (nodes, prim_indices, live) = sah::build_sah(prims, &params);
        Bvh::from_flat(prims, nodes, prim_indices, live, recipe, start, binary)
    }

    /// Builds a BVH over `prims` by splitting at the median centroid on the longest axis (see
    /// `median.rs`).
    pub fn build_median<P: Primitives + ?Sized>(prims: &P, params: &MedianParams) -> Bvh {
        Bvh::median(prims, params, Binary::DropForMesh)
    }

    pub(crate) fn median<P: Primitives + ?Sized>(prims: &P, params: &MedianParams, binary: Binary) -> Bvh {
        let start = Instant::now();
        let bvh_params = BvhParams { max_leaf_prims: params.max_leaf_prims, ..BvhParams::default() };
        let (nodes, prim_indices, live) = median::build_median(prims, &bvh_params.sanitized());
        Bvh::from_flat(prims, nodes, prim_indices, live, Recipe::Median(*params), start, binary)
    }

    /// Builds a BVH over `prims` bottom-up, by the exact greedy method or PLOC (see `bottom_up/`).
    pub fn build_bottom_up<P: Primitives + ?Sized>(prims: &P, params: &BottomUpParams) -> Bvh {
        Bvh::bottom_up(prims, params, Binary::DropForMesh)
    }

    pub(crate) fn bottom_up<P: Primitives + ?Sized>(prims: &P, params: &BottomUpParams, binary: Binary) -> Bvh {
        let start = Instant::now();
        let (nodes, prim_indices, live) = bottom_up::build(prims, params);
        Bvh::from_flat(prims, nodes, prim_indices, live, Recipe::BottomUp(params.clone()), start, binary)
    }

    /// Wraps a flat node array written by any builder (the traversal and checks are shared), collapses
    /// it, drops it for a mesh unless told to keep it, and records the build time since `start`.
    pub(crate) fn from_flat<P: Primitives + ?Sized>(
        prims: &P,
        nodes: Vec<Node>,
        prim_indices: Vec<u32>,
        live: usize,
        recipe: Recipe,
        start: Instant,
        binary: Binary,
    ) -> Bvh {
        let kind = recipe.kind();
        let drop = binary == Binary::DropForMesh && prims.triangle_mesh().is_some();
        // The statistics describe the binary tree, so when it is to be dropped they are taken now, as
        // part of the build, by a walk that needs nothing from the collapse: the two run side by side.
        let collapse = || Wide::collapse(&nodes, &prim_indices, prims);
        let stats = || drop.then(|| binary_stats(&nodes, prim_indices.len(), kind, 0, Duration::ZERO));
        let (wide, dropped_stats) =
            if build::one_thread() { (collapse(), stats()) } else { rayon::join(collapse, stats) };
        let bounds = nodes.first().map_or(Aabb::EMPTY, Node::bounds);
        let primitives = prim_indices.len();
        let mut bvh = Bvh {
            nodes,
            prim_indices,
            live,
            primitives,
            bounds,
            wide,
            dropped_stats,
            recipe,
            build_time: Duration::ZERO,
        };
        if drop {
            bvh.nodes = Vec::new();
            bvh.prim_indices = Vec::new();
        }
        // Otherwise statistics are computed when asked for (a walk over every node): not part of the build.
        bvh.build_time = start.elapsed();
        bvh
    }

    /// True when the binary tree and the index array were dropped after the collapse (a mesh BVH from
    /// the public builders): [`Bvh::nodes`] and [`Bvh::prim_indices`] are then empty.
    pub fn binary_dropped(&self) -> bool {
        self.dropped_stats.is_some()
    }

    /// The 8-wide tree that queries traverse.
    pub fn wide(&self) -> &Wide {
        &self.wide
    }

    /// The flat node array; node 0 is the root (empty when no primitive can be hit, or when dropped:
    /// see [`Bvh::binary_dropped`]).
    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// Primitive indices in leaf order; leaves refer to ranges of it (empty when dropped).
    pub fn prim_indices(&self) -> &[u32] {
        &self.prim_indices
    }

    fn compute_stats(&self, kind: &'static str, build_time: Duration) -> AccelStats {
        let bytes = std::mem::size_of::<Self>()
            + self.nodes.len() * std::mem::size_of::<Node>()
            + self.prim_indices.len() * std::mem::size_of::<u32>()
            + self.wide.bytes();
        if let Some(s) = &self.dropped_stats {
            return AccelStats { bytes, build_time, ..s.clone() };
        }
        binary_stats(&self.nodes, self.prim_indices.len(), kind, bytes, build_time)
    }
}

/// The statistics of binary tree `nodes` over `primitives` primitives.
fn binary_stats(
    nodes: &[Node],
    primitives: usize,
    kind: &'static str,
    bytes: usize,
    build_time: Duration,
) -> AccelStats {
    let mut tally = StatsTally::new(kind, primitives, nodes.len(), bytes, build_time);
    let Some(root) = nodes.first() else {
        return tally.finish();
    };
    // Areas relative to the root's; a root of zero area (all primitives on one line or point)
    // makes every node equally likely to be visited.
    let root_area = root.bounds().area_f64();
    let rel = |n: &Node| {
        if root_area > 0.0 {
            n.bounds().area_f64() / root_area
        } else {
            1.0
        }
    };
    let mut stack = vec![(0usize, 0usize)];
    while let Some((i, depth)) = stack.pop() {
        let n = &nodes[i];
        if n.is_leaf() {
            tally.leaf(depth, n.count as usize, rel(n));
        } else {
            tally.inner(rel(n));
            stack.push((i + 1, depth + 1));
            stack.push((n.offset as usize, depth + 1));
        }
    }
    tally.finish()
}

impl<P: Primitives + ?Sized> Accel<P> for Bvh {
    fn bounds(&self) -> Aabb {
        self.bounds
    }

    fn intersect(&self, prims: &P, ray: &Ray, t_max: f32) -> Option<Hit> {
        wide::intersect_with::<P, false>(
            Kernel::detect(),
            &self.wide,
            &self.prim_indices,
            prims,
            ray,
            t_max,
            &mut TraversalCounts::default(),
        )
    }

    fn intersect_counted(&self, prims: &P, ray: &Ray, t_max: f32, counts: &mut TraversalCounts) -> Option<Hit> {
        wide::intersect_with::<P, true>(Kernel::detect(), &self.wide, &self.prim_indices, prims, ray, t_max, counts)
    }

    fn intersect_many(&self, prims: &P, rays: &[Ray], t_max: &[f32], out: &mut [Option<Hit>]) {
        wide::intersect_many_with(Kernel::detect(), &self.wide, &self.prim_indices, prims, rays, t_max, out)
    }

    fn intersect_many_coherent(&self, prims: &P, rays: &[Ray], t_max: &[f32], out: &mut [Option<Hit>]) {
        wide::intersect_coherent_with(Kernel::detect(), &self.wide, &self.prim_indices, prims, rays, t_max, out)
    }

    fn boxes_at_depth(&self, prims: &P, depth: usize) -> Vec<Aabb> {
        if self.binary_dropped() {
            return Accel::<P>::boxes_at_depth(&self.recipe.build_kept(prims), prims, depth);
        }
        let mut out = Vec::new();
        let mut stack = if self.nodes.is_empty() { vec![] } else { vec![(0usize, 0usize)] };
        while let Some((i, d)) = stack.pop() {
            let n = &self.nodes[i];
            if d == depth {
                out.push(n.bounds());
            } else if !n.is_leaf() {
                stack.push((n.offset as usize, d + 1));
                stack.push((i + 1, d + 1));
            }
        }
        out
    }

    fn occluded(&self, prims: &P, ray: &Ray, t_max: f32) -> bool {
        wide::occluded_with(Kernel::detect(), &self.wide, &self.prim_indices, prims, ray, t_max)
    }

    fn occluded_many(&self, prims: &P, rays: &[Ray], t_max: &[f32], out: &mut [bool]) {
        wide::occluded_many_with(Kernel::detect(), &self.wide, &self.prim_indices, prims, rays, t_max, out)
    }

    fn closest_point(&self, prims: &P, p: DVec3, max_dist2: f64) -> Option<Nearest> {
        nearest::query(p, max_dist2, 0.0, |best| wide::closest_point(&self.wide, &self.prim_indices, prims, best))
    }

    fn stats(&self) -> AccelStats {
        self.compute_stats(self.recipe.kind(), self.build_time)
    }

    fn validate(&self, prims: &P) -> Result<(), String> {
        if !self.binary_dropped() {
            validate::validate(&self.nodes, &self.prim_indices, self.live, prims)?;
        }
        match prims.triangle_mesh() {
            Some(mesh) if self.wide.has_blocks() => self.wide.validate(mesh, self.primitives, self.live, self.bounds),
            _ => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests;
