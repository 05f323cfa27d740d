//! The collapse on one thread: one depth-first walk that writes each wide node, and its leaves'
//! blocks, when it reaches it (the parent module says what the nodes hold). A node's inner children
//! take consecutive slots when the node is written, and are walked after it, in lane order. This
//! layout is the reference that the parallel passes of `collapse.rs` reproduce byte for byte (the
//! thread-count test compares the two); on one thread the walk is the cheaper of the two, reading the
//! binary tree once and copying nothing.

use super::{advise_huge_pages, LeafBlock, Node8, Ref, WIDTH};
use crate::accel::bvh::Node;
use crate::geometry::{Tri4, TriangleMesh};
use crate::math::Aabb;

/// The wide nodes and the blocks of `bin`, whose root is an inner node.
pub(super) fn collapse(bin: &[Node], indices: &[u32], mesh: Option<&TriangleMesh>) -> (Vec<Node8>, Vec<LeafBlock>) {
    let mut c = Collapse { bin, indices, mesh, nodes: Vec::new(), blocks: Vec::new() };
    // Exact room for the blocks and an upper bound for the nodes (each wide node takes at least one
    // binary inner node), so that neither array moves after its pages are advised.
    c.nodes = Vec::with_capacity(bin.len() / 2);
    advise_huge_pages(&c.nodes);
    if mesh.is_some() {
        let blocks = bin.iter().filter(|b| b.is_leaf()).map(|b| (b.count as usize).div_ceil(4)).sum();
        c.blocks = Vec::with_capacity(blocks);
        advise_huge_pages(&c.blocks);
    }
    c.nodes.push(Node8::EMPTY);
    c.node(0, 0);
    (c.nodes, c.blocks)
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
            node.set_lane(lane, bounds, r);
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

/// Appends the block of triangles `ids` (one to four) to `blocks`; returns its index. Lanes past the
/// last triangle repeat it (the traversal never tests them).
fn push_block(blocks: &mut Vec<LeafBlock>, mesh: &TriangleMesh, ids: &[u32]) -> u32 {
    let prim: [u32; 4] = std::array::from_fn(|l| ids[l.min(ids.len() - 1)]);
    let tris = prim.map(|i| mesh.triangle(i as usize));
    blocks.push(LeafBlock { tris: Tri4::new(&tris[..ids.len()]), prim });
    blocks.len() as u32 - 1
}
