//! The 8-wide form of a binary BVH, which is what queries traverse (Wald, Benthin and Boulos 2008,
//! "Getting rid of packets"; Embree's BVH8): every binary tree, whatever its builder, is collapsed
//! into nodes of up to eight children whose boxes are stored as structure-of-arrays `f32` lanes, so
//! one ray is tested against eight boxes at once (`kernel.rs`: AVX2 when the processor has it,
//! else two SSE halves). Eight children rather than four: a query visits about half as many nodes, and
//! node fetches are where incoherent rays spend their time.
//!
//! Collapse: starting from a binary node's two children, the inner child with the largest surface area
//! is repeatedly replaced by its own two children until there are eight, or only leaves (the SAH
//! probability of being visited decides which level to skip). Leaves keep their ranges of the binary
//! tree's primitive order.
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
//! Queries, one job per file: the node test in three kernels (`kernel.rs`), what a query does at a
//! leaf (`leaves.rs`), the dispatch over kernel and kind of leaf (`dispatch.rs`), the node visit and pop
//! shared by the closest-hit queries (`visit.rs`), the closest-hit query (`closest.rs`), its batch form
//! (`batch.rs`) and the any-hit query (`any_hit.rs`).

mod any_hit;
mod batch;
mod check;
mod closest;
mod dispatch;
mod kernel;
mod leaves;
mod visit;

pub(super) use any_hit::occluded;
pub(super) use any_hit::occluded_many;
#[cfg(test)]
pub(super) use any_hit::occluded_many_with;
#[cfg(test)]
pub(super) use any_hit::occluded_with;
pub(super) use batch::intersect_many;
#[cfg(test)]
pub(super) use batch::intersect_many_with;
pub(super) use closest::intersect;
#[cfg(test)]
pub(super) use closest::intersect_with;
#[cfg(test)]
pub(super) use kernel::Avx2;
pub(super) use kernel::Kernel;

use super::Node;
use crate::accel::Primitives;
use crate::geometry::{Tri4, TriangleMesh};
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

/// What the collapse reads and writes.
struct Collapse<'a> {
    bin: &'a [Node],
    indices: &'a [u32],
    mesh: Option<&'a TriangleMesh>,
    nodes: Vec<Node8>,
    blocks: Vec<LeafBlock>,
}

impl Collapse<'_> {
    /// The reference to binary leaf `b`, copying its triangles into blocks for a mesh.
    fn leaf(&mut self, b: &Node) -> Ref {
        let count = b.count as u32;
        let Some(mesh) = self.mesh else { return Ref { child: b.offset, count } };
        let first = self.blocks.len() as u32;
        let range = b.offset as usize..b.offset as usize + b.count as usize;
        for ids in self.indices[range].chunks(4) {
            push_block(&mut self.blocks, mesh, ids);
        }
        Ref { child: first, count }
    }

    /// Binary leaf `b` of a mesh as one reference per block of four triangles, each with the box of its
    /// own triangles: the leaf's triangles sorted along its box's longest axis, then cut into blocks,
    /// so that each block is a compact piece of the leaf (a ray that meets the leaf's box often meets
    /// only one of them).
    fn split_leaf(&mut self, b: &Node, mesh: &TriangleMesh) -> Vec<(Aabb, Ref)> {
        let axis = b.bounds().longest_axis();
        let mut ids: Vec<u32> = self.indices[b.offset as usize..b.offset as usize + b.count as usize].to_vec();
        let key = |i: u32| {
            let [p0, p1, p2] = mesh.triangle(i as usize);
            p0[axis] + p1[axis] + p2[axis]
        };
        ids.sort_by(|&x, &y| key(x).total_cmp(&key(y)).then(x.cmp(&y)));
        ids.chunks(4)
            .map(|chunk| {
                let bounds = Aabb::from_points(chunk.iter().flat_map(|&i| mesh.triangle(i as usize)));
                (bounds, Ref { child: push_block(&mut self.blocks, mesh, chunk), count: chunk.len() as u32 })
            })
            .collect()
    }

    /// Writes the wide node for binary inner node `i` at `index` (already reserved), then its subtree.
    /// The inner children of a node get consecutive slots, as in Embree: a ray that enters several of
    /// them reads neighbouring memory.
    fn node(&mut self, index: usize, i: usize) {
        let bin = self.bin;
        let mut kids = [0usize; WIDTH];
        kids[0] = i + 1;
        kids[1] = bin[i].offset as usize;
        let mut n = 2;
        while n < WIDTH {
            // Open the inner child most likely to be visited.
            let best = (0..n).filter(|&k| !bin[kids[k]].is_leaf()).max_by(|&a, &b| {
                let (sa, sb) = (bin[kids[a]].bounds().area_f64(), bin[kids[b]].bounds().area_f64());
                sa.total_cmp(&sb)
            });
            let Some(k) = best else { break };
            let open = kids[k];
            kids[k] = open + 1;
            kids[n] = bin[open].offset as usize;
            n += 1;
        }
        // Lanes left over go to the blocks of leaves of more than one block, largest leaves first:
        // a lane costs nothing in the node test, and a block behind its own box is tested only by
        // rays that meet that box.
        let mut split = [false; WIDTH];
        if self.mesh.is_some() {
            let mut free = WIDTH - n;
            let mut leaves: Vec<usize> = (0..n).filter(|&k| bin[kids[k]].count > 4).collect();
            leaves.sort_by(|&a, &b| bin[kids[b]].bounds().area_f64().total_cmp(&bin[kids[a]].bounds().area_f64()));
            for k in leaves {
                let extra = (bin[kids[k]].count as usize).div_ceil(4) - 1;
                if extra <= free {
                    free -= extra;
                    split[k] = true;
                }
            }
        }
        let mut node = Node8::EMPTY;
        let mut inner = [(0usize, 0usize); WIDTH];
        let mut n_inner = 0;
        let mut lane = 0;
        let mut put = |node: &mut Node8, bounds: Aabb, r: Ref| {
            for a in 0..3 {
                node.min[a][lane] = bounds.min[a];
                node.max[a][lane] = bounds.max[a];
            }
            node.child[lane] = r.child;
            node.count[lane] = r.count;
            lane += 1;
        };
        for (k, &c) in kids[..n].iter().enumerate() {
            let b = &bin[c];
            if split[k] {
                let mesh = self.mesh.expect("only mesh leaves are split");
                for (bounds, r) in self.split_leaf(b, mesh) {
                    put(&mut node, bounds, r);
                }
                continue;
            }
            let r = if b.is_leaf() {
                self.leaf(b)
            } else {
                let slot = self.nodes.len();
                self.nodes.push(Node8::EMPTY);
                inner[n_inner] = (slot, c);
                n_inner += 1;
                Ref { child: slot as u32, count: 0 }
            };
            put(&mut node, b.bounds(), r);
        }
        self.nodes[index] = node;
        for &(slot, c) in &inner[..n_inner] {
            self.node(slot, c);
        }
    }
}

impl Wide {
    /// Collapses the binary tree `bin` (depth-first layout) whose leaves refer to `indices`.
    pub(super) fn collapse<P: Primitives + ?Sized>(bin: &[Node], indices: &[u32], prims: &P) -> Wide {
        let mesh = prims.triangle_mesh();
        let mut c = Collapse { bin, indices, mesh, nodes: Vec::new(), blocks: Vec::new() };
        let root = match bin.first() {
            None => None,
            Some(root) if root.is_leaf() => Some(c.leaf(root)),
            Some(_) => {
                // Exact room for the blocks and an upper bound for the nodes (each wide node takes at
                // least one binary inner node), so that neither array moves after its pages are advised.
                c.nodes = Vec::with_capacity(bin.len() / 2);
                advise_huge_pages(&c.nodes);
                if mesh.is_some() {
                    let blocks = bin.iter().filter(|b| b.is_leaf()).map(|b| (b.count as usize).div_ceil(4)).sum();
                    c.blocks = Vec::with_capacity(blocks);
                    advise_huge_pages(&c.blocks);
                }
                c.nodes.push(Node8::EMPTY);
                c.node(0, 0);
                Some(Ref { child: 0, count: 0 })
            }
        };
        Wide { nodes: c.nodes, root, blocks: mesh.map(|_| c.blocks) }
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

/// Appends the block of triangles `ids` (one to four) to `blocks`; returns its index. Lanes past the
/// last triangle repeat it (the traversal never tests them).
fn push_block(blocks: &mut Vec<LeafBlock>, mesh: &TriangleMesh, ids: &[u32]) -> u32 {
    let prim: [u32; 4] = std::array::from_fn(|l| ids[l.min(ids.len() - 1)]);
    let tris = prim.map(|i| mesh.triangle(i as usize));
    blocks.push(LeafBlock { tris: Tri4::new(&tris[..ids.len()]), prim });
    blocks.len() as u32 - 1
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
