//! The collapse on one thread: one depth-first walk that writes each wide node, and its leaves'
//! blocks, when it reaches it (the parent module says what the nodes hold). A node's inner children
//! take consecutive slots when the node is written, and are walked after it, in lane order. This
//! layout is the reference that the parallel passes of `collapse.rs` reproduce byte for byte (the
//! thread-count test compares the two); on one thread the walk is the cheaper of the two, reading the
//! binary tree once and copying nothing.

use super::choose::{make_block, plan_node, sort_leaf};
use super::{advise_huge_pages, LeafBlock, Node8, Ref, WIDTH};
use crate::accel::bvh::Node;
use crate::geometry::TriangleMesh;
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

impl<'a> Collapse<'a> {
    /// The triangle indices of binary leaf `b`.
    fn ids(&self, b: &Node) -> &'a [u32] {
        &self.indices[b.offset as usize..b.offset as usize + b.count as usize]
    }

    /// The reference to binary leaf `b`, copying its triangles into blocks for a mesh.
    fn leaf(&mut self, b: &Node) -> Ref {
        let count = b.count as u32;
        let Some(mesh) = self.mesh else { return Ref { child: b.offset, count } };
        let first = self.blocks.len() as u32;
        for ids in self.ids(b).chunks(4) {
            self.blocks.push(make_block(mesh, ids));
        }
        Ref { child: first, count }
    }

    /// Binary leaf `b` of a mesh as one reference per block of four triangles, each with the box of its
    /// own triangles ([`sort_leaf`] orders them).
    fn split_leaf(&mut self, b: &Node, mesh: &TriangleMesh) -> Vec<(Aabb, Ref)> {
        let ids = self.ids(b);
        let sorted = sort_leaf(b, ids, mesh);
        let mut out = Vec::with_capacity(ids.len().div_ceil(4));
        for chunk in sorted[..ids.len()].chunks(4) {
            let bounds = Aabb::from_points(chunk.iter().flat_map(|&i| mesh.triangle(i as usize)));
            self.blocks.push(make_block(mesh, chunk));
            out.push((bounds, Ref { child: self.blocks.len() as u32 - 1, count: chunk.len() as u32 }));
        }
        out
    }

    /// Writes the wide node for binary inner node `i` at `index` (already reserved), then its subtree.
    /// Its children are [`plan_node`]'s; the inner ones get consecutive slots, as in Embree: a ray
    /// that enters several of them reads neighbouring memory.
    fn node(&mut self, index: usize, i: usize) {
        let bin = self.bin;
        let plan = plan_node(bin, self.mesh.is_some(), i);
        let mut node = Node8::EMPTY;
        let mut inner = [(0usize, 0usize); WIDTH];
        let mut n_inner = 0;
        let mut lane = 0;
        let mut put = |node: &mut Node8, bounds: Aabb, r: Ref| {
            node.set_lane(lane, bounds, r);
            lane += 1;
        };
        for (k, &c) in plan.kids[..plan.n as usize].iter().enumerate() {
            let (c, b) = (c as usize, &bin[c as usize]);
            if plan.split & (1 << k) != 0 {
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
