//! The 8-wide form of a binary BVH, which is what queries traverse (Wald, Benthin and Boulos 2008,
//! "Getting rid of packets"; Embree's BVH8): every binary tree, whatever its builder, is collapsed
//! into nodes of up to eight children whose boxes are stored as structure-of-arrays `f32` lanes, so
//! one ray is tested against eight boxes at once (`kernel.rs`: AVX-512 or AVX2 when the processor has
//! it, else two SSE halves). Eight children rather than four: a query visits about half as many nodes, and
//! node fetches are where incoherent rays spend their time.
//!
//! Collapse: starting from a binary node's two children, the inner child with the largest surface area
//! is repeatedly replaced by its own two children until there are eight, or only leaves (the SAH
//! probability of being visited decides which level to skip). Leaves keep their ranges of the binary
//! tree's primitive order. The nodes are laid out as a depth-first walk writes them (a node's inner
//! children in consecutive slots, taken when the node is visited), whatever the thread count:
//! `collapse.rs` plans, places and fills them in parallel and gets that layout byte for byte.
//!
//! When the primitives are a triangle mesh ([`Primitives::triangle_mesh`]), the corners of every
//! leaf's triangles are copied, in leaf order, into blocks of four SIMD lanes ([`LeafBlock`]), so the
//! leaf loop reads consecutive memory instead of chasing two indices per triangle and tests four
//! triangles at once ([`crate::geometry::intersect_triangles4`]); that test gives, lane by lane, the
//! scalar watertight test's result on the same corner values, so hits are bit for bit those of brute
//! force. A node's unused lanes go to the blocks of its leaves of more than one block: such a leaf's
//! triangles are sorted along its longest axis and each block of four gets a lane with the box of its
//! own triangles (still a box that holds its triangles, so the traversal's argument is untouched).
//! Other primitives are asked through [`Primitives::intersect`].
//!
//! Cost: 256 bytes per node (about `n / (5 * leaf size)` nodes), 160 bytes per block of up to four
//! triangles; the collapse is linear in the binary tree's size (plus a sort of each split leaf's few
//! triangles).
//!
//! The collapse is in `collapse.rs` (and `walk.rs`, its one-thread form). Queries, one job per file: the node test in four kernels (`kernel.rs`), what a query does at a
//! leaf (`leaves.rs`), the dispatch over kernel and kind of leaf (`dispatch.rs`), the node visit and pop
//! shared by the closest-hit queries (`visit.rs`), the closest-hit query (`closest.rs`), its batch form
//! (`batch.rs`) and its packets of coherent rays (`packet.rs`), the any-hit query (`any_hit.rs`) and the
//! closest-point query (`nearest.rs`).

mod any_hit;
mod batch;
mod check;
mod choose;
mod closest;
mod collapse;
mod dispatch;
mod kernel;
mod leaves;
mod nearest;
mod packet;
#[cfg(test)]
mod packet_tests;
mod visit;
mod walk;

pub(super) use any_hit::{occluded_many_with, occluded_with};
pub(super) use batch::intersect_many_with;
pub(super) use closest::intersect_with;
#[cfg(test)]
pub(super) use collapse::PLAN_PARALLEL;
pub(super) use kernel::Kernel;
#[cfg(test)]
pub(super) use kernel::{Avx2, Avx512};
pub use kernel::{Isa, MAX_ISA_VAR};
pub(super) use nearest::closest_point;
pub(super) use packet::intersect_coherent_with;

use super::Node;
use crate::accel::Primitives;
use crate::geometry::Tri4;
use crate::math::Aabb;

/// Children per wide node.
pub const WIDTH: usize = 8;

/// One 8-wide node: boxes of up to eight children as lanes (`[axis][lane]`), and what each child is.
/// Unused lanes have an inverted infinite box (min `+inf`, max `-inf`), which every ray misses.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
pub struct Node8 {
    /// Lower corners, per axis then lane.
    pub min: [[f32; WIDTH]; 3],
    /// Upper corners, per axis then lane.
    pub max: [[f32; WIDTH]; 3],
    /// Per lane: the child node's index (inner child), or its first primitive in leaf order (leaf).
    pub child: [u32; WIDTH],
    /// Per lane: 0 for an inner child (or an unused lane), else the leaf's primitive count.
    pub count: [u32; WIDTH],
}

const _: () = assert!(std::mem::size_of::<Node8>() == 256);

// SAFETY: `Node8` is `repr(C)` of arrays of `f32` and `u32` only (every bit pattern valid, all zeros
// included), 256 bytes with no padding (asserted above: 48 floats and 16 words fill it), so it may be
// viewed as plain bytes or floats (`kernel.rs` reads its boxes as one `[f32; 64]`).
unsafe impl bytemuck::Zeroable for Node8 {}
// SAFETY: as for `Zeroable` above; `Node8` is also `Copy` and `'static`.
unsafe impl bytemuck::Pod for Node8 {}

impl Node8 {
    const EMPTY: Node8 = Node8 {
        min: [[f32::INFINITY; WIDTH]; 3],
        max: [[f32::NEG_INFINITY; WIDTH]; 3],
        child: [u32::MAX; WIDTH],
        count: [0; WIDTH],
    };

    /// Sets lane `lane` to the child `r` inside `bounds`.
    #[inline]
    fn set_lane(&mut self, lane: usize, bounds: Aabb, r: Ref) {
        for a in 0..3 {
            self.min[a][lane] = bounds.min[a];
            self.max[a][lane] = bounds.max[a];
        }
        self.child[lane] = r.child;
        self.count[lane] = r.count;
    }
}

/// A reference to a subtree: an inner node (`count == 0`) or a leaf.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Ref {
    pub child: u32,
    pub count: u32,
}

/// Four triangles of one leaf, as SIMD lanes, and their primitive indices. A leaf of `n` triangles is
/// `ceil(n / 4)` consecutive blocks; lanes past `n` in its last block repeat a triangle and are never
/// tested.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(16))]
pub struct LeafBlock {
    /// The corners.
    pub tris: Tri4,
    /// Each lane's primitive index.
    pub prim: [u32; 4],
}

/// The 8-wide tree and, for triangle meshes, the triangles in leaf order.
#[derive(Debug, Clone, Default)]
pub struct Wide {
    nodes: Vec<Node8>,
    /// The root: node 0, or a single leaf; `None` for an empty tree.
    root: Option<Ref>,
    /// For triangle meshes, the leaves' triangles (leaves then refer to their first block instead of
    /// their first primitive index).
    blocks: Option<Vec<LeafBlock>>,
}

impl Wide {
    /// Collapses the binary tree `bin` (depth-first layout) whose leaves refer to `indices`.
    pub(super) fn collapse<P: Primitives + ?Sized>(bin: &[Node], indices: &[u32], prims: &P) -> Wide {
        let mesh = prims.triangle_mesh();
        if bin.is_empty() {
            return Wide { nodes: Vec::new(), root: None, blocks: mesh.map(|_| Vec::new()) };
        }
        let (nodes, root, blocks) = collapse::collapse(bin, indices, mesh);
        Wide { nodes, root: Some(root), blocks: mesh.map(|_| blocks) }
    }

    /// Bytes of the wide nodes and the triangle blocks.
    pub fn bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<Node8>()
            + self.blocks.as_ref().map_or(0, |b| b.len() * std::mem::size_of::<LeafBlock>())
    }

    /// The wide nodes (node 0 is the root when the root is not a leaf).
    pub fn nodes(&self) -> &[Node8] {
        &self.nodes
    }

    /// The triangle blocks (empty unless the primitives are a mesh).
    pub fn blocks(&self) -> &[LeafBlock] {
        self.blocks.as_deref().unwrap_or(&[])
    }
}

/// Asks Linux to back the 2 MiB-aligned part of `v`'s allocation with transparent huge pages, as
/// Embree does: incoherent rays fetch nodes and blocks all over a large tree, and with 4 KiB pages
/// nearly every such fetch also misses the TLB. Called before the memory is first written; a no-op on
/// other systems, for small arrays, and when the kernel declines.
fn advise_huge_pages<T>(v: &Vec<T>) {
    #[cfg(target_os = "linux")]
    {
        const HUGE: usize = 2 << 20;
        let start = v.as_ptr() as usize;
        let end = start + v.capacity() * std::mem::size_of::<T>();
        let (a, b) = (start.next_multiple_of(HUGE), end / HUGE * HUGE);
        if b > a {
            // SAFETY: `a..b` lies inside the vector's allocation, and the advice changes no content.
            unsafe {
                libc::madvise(a as *mut libc::c_void, b - a, libc::MADV_HUGEPAGE);
            }
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = v;
}
