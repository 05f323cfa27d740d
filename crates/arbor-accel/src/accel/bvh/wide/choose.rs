//! What the collapse decides, shared by its one-thread walk (`walk.rs`) and its parallel passes
//! (`collapse.rs`), so that both build the same tree: which binary nodes a wide node lifts and which of
//! its leaves get a lane per block ([`plan_node`]), the order of a split leaf's triangles
//! ([`sort_leaf`]) and a block of four ([`make_block`]).

use super::{LeafBlock, WIDTH};
use crate::accel::bvh::{Node, LEAF_HARD_MAX};
use crate::geometry::{Tri4, TriangleMesh};

/// One wide node, as planned.
#[derive(Debug, Clone, Copy)]
pub(super) struct Plan {
    /// The binary nodes that become its children, in lane order (a split leaf takes several lanes).
    pub(super) kids: [u32; WIDTH],
    pub(super) n: u8,
    /// Bit `k`: child `k` is a leaf whose blocks each get a lane of their own.
    pub(super) split: u8,
    /// Children that are inner nodes.
    pub(super) inner: u8,
    /// Blocks of its leaf children (0 unless the primitives are a mesh).
    pub(super) blocks: u32,
    /// Plans in its subtree, its own included.
    pub(super) size: u32,
}

/// The children of the wide node that lifts binary inner node `i`: starting from its two children,
/// the inner child with the largest surface area is replaced by its own two children until there are
/// eight, or only leaves (the SAH probability of being visited decides which level to skip). Then the
/// lanes left over go to the blocks of leaves of more than one block, largest leaves first: a lane
/// costs nothing in the node test, and a block behind its own box is tested only by rays that meet
/// that box.
pub(super) fn plan_node(bin: &[Node], mesh: bool, i: usize) -> Plan {
    let area = |c: u32| bin[c as usize].bounds().area_f64();
    let mut kids = [0u32; WIDTH];
    let mut areas = [0.0f64; WIDTH];
    kids[0] = i as u32 + 1;
    kids[1] = bin[i].offset;
    areas[0] = area(kids[0]);
    areas[1] = area(kids[1]);
    let mut n = 2;
    while n < WIDTH {
        // On equal areas the last one wins, as `Iterator::max_by` does.
        let best = (0..n).filter(|&k| !bin[kids[k] as usize].is_leaf()).max_by(|&a, &b| areas[a].total_cmp(&areas[b]));
        let Some(k) = best else { break };
        let open = kids[k] as usize;
        kids[k] = open as u32 + 1;
        kids[n] = bin[open].offset;
        areas[k] = area(kids[k]);
        areas[n] = area(kids[n]);
        n += 1;
    }
    let count = |k: usize| bin[kids[k] as usize].count as usize;
    let mut split = 0u8;
    if mesh {
        let mut free = WIDTH - n;
        let mut leaves = [0usize; WIDTH];
        let mut m = 0;
        for k in (0..n).filter(|&k| count(k) > 4) {
            leaves[m] = k;
            m += 1;
        }
        // Stable, so equal areas keep lane order.
        leaves[..m].sort_by(|&a, &b| areas[b].total_cmp(&areas[a]));
        for &k in &leaves[..m] {
            let extra = count(k).div_ceil(4) - 1;
            if extra <= free {
                free -= extra;
                split |= 1 << k;
            }
        }
    }
    let inner = (0..n).filter(|&k| count(k) == 0).count() as u8;
    let blocks = if mesh { (0..n).map(|k| count(k).div_ceil(4) as u32).sum() } else { 0 };
    Plan { kids, n: n as u8, split, inner, blocks, size: 0 }
}

/// The triangles `ids` of leaf `b` sorted along its box's longest axis, to be cut in blocks of four:
/// each block is then a compact piece of the leaf (a ray that meets the leaf's box often meets only
/// one of them).
pub(super) fn sort_leaf(b: &Node, ids: &[u32], mesh: &TriangleMesh) -> [u32; LEAF_HARD_MAX] {
    let axis = b.bounds().longest_axis();
    let key = |i: u32| {
        let [p0, p1, p2] = mesh.triangle(i as usize);
        p0[axis] + p1[axis] + p2[axis]
    };
    let mut sorted = [0u32; LEAF_HARD_MAX];
    sorted[..ids.len()].copy_from_slice(ids);
    sorted[..ids.len()].sort_by(|&x, &y| key(x).total_cmp(&key(y)).then(x.cmp(&y)));
    sorted
}

/// The block of triangles `ids` (one to four). Lanes past the last triangle repeat it (the traversal
/// never tests them).
pub(super) fn make_block(mesh: &TriangleMesh, ids: &[u32]) -> LeafBlock {
    let prim: [u32; 4] = std::array::from_fn(|l| ids[l.min(ids.len() - 1)]);
    let tris = prim.map(|i| mesh.triangle(i as usize));
    LeafBlock { tris: Tri4::new(&tris[..ids.len()]), prim }
}
