//! What every BVH builder shares (`sah/`, `median.rs`, `bottom_up/`): the builder's view of a
//! primitive ([`BuildPrim`]), the primitives kept out of every tree (empty or non-finite bounds, which
//! can never be hit and would make every ancestor's box useless), the temporary tree of boxed nodes
//! that parallel builds write ([`BuildNode`]), and its flattening into the depth-first node array
//! that [`super::Bvh`] stores (first child right after its parent, the second child's index stored).
//!
//! Builders split nodes of at least [`PARALLEL_THRESHOLD`] primitives into halves built with
//! `rayon::join`; since each half owns a disjoint slice of the primitive array and every decision
//! depends only on that slice, the tree is identical for any thread count.

use std::mem::MaybeUninit;

use rayon::prelude::*;

use super::{Node, LEAF_HARD_MAX};
use crate::accel::Primitives;
use crate::math::{Aabb, Vec3};

/// Nodes with at least this many primitives build their two children in parallel.
pub(super) const PARALLEL_THRESHOLD: usize = 4096;

/// True when the build runs on one thread (or under Miri, where starting rayon's pool breaks Stacked
/// Borrows in crossbeam-epoch): then the builders take their serial paths, which give the same result
/// without handing work to the pool (each hand-off wakes a pool thread and waits for it).
pub(super) fn one_thread() -> bool {
    cfg!(miri) || rayon::current_num_threads() == 1
}

/// What the builder knows about one primitive.
#[derive(Debug, Clone, Copy)]
pub(super) struct BuildPrim {
    /// Bounds, finite and not empty.
    pub bounds: Aabb,
    /// The point the builders sort and split by.
    pub centroid: Vec3,
    /// The primitive's index in the input.
    pub index: u32,
}

/// The temporary tree, shared by every builder: leaves refer to ranges of the reordered primitives.
pub(super) enum BuildNode {
    Leaf {
        bounds: Aabb,
        first: u32,
        count: u16,
    },
    Inner {
        bounds: Aabb,
        axis: u8,
        children: Box<[BuildNode; 2]>,
    },
    /// A subtree already in the flat layout, second-child indices relative to its own first node (the
    /// SAH builder writes subtrees below the parallel threshold this way: no boxed node to allocate,
    /// walk and free for the bulk of the tree).
    Flat(Vec<Node>),
}

/// The builder's view of every primitive that can be hit, in index order, and the indices of those
/// that cannot (empty or non-finite bounds), which every builder keeps out of the tree.
pub(super) fn split_live<P: Primitives + ?Sized>(prims: &P) -> (Vec<BuildPrim>, Vec<u32>) {
    assert!(prims.len() <= u32::MAX as usize, "a BVH indexes at most 2^32 - 1 primitives");
    let live: Vec<BuildPrim> = (0..prims.len()).into_par_iter().filter_map(|i| build_prim(prims, i)).collect();
    // Rare: look for the primitives left out only when there are some.
    let dead = if live.len() < prims.len() {
        (0..prims.len()).filter(|&i| build_prim(prims, i).is_none()).map(|i| i as u32).collect()
    } else {
        Vec::new()
    };
    (live, dead)
}

/// The flat array of `root` (whose leaves refer to ranges of `live`, in that order), the index array
/// (`live`, then `dead`) and the number of live primitives: what [`super::Bvh::from_flat`] takes.
pub(super) fn finish(root: Option<&BuildNode>, live: &[BuildPrim], dead: &[u32]) -> (Vec<Node>, Vec<u32>, usize) {
    let mut nodes = Vec::new();
    if let Some(root) = root {
        // About two nodes per leaf of a few primitives; growing past it costs a copy, cheaper than
        // walking the tree to count.
        nodes.reserve(live.len() / 2);
        flatten(root, &mut nodes);
    }
    let indices = live.iter().map(|p| p.index).chain(dead.iter().copied()).collect();
    (nodes, indices, live.len())
}

/// The builder's view of primitive `i`, or `None` when its bounds are empty or not finite: such a
/// primitive can never be hit, and its box would make every ancestor's box useless.
fn build_prim<P: Primitives + ?Sized>(prims: &P, i: usize) -> Option<BuildPrim> {
    let bounds = prims.bounds(i);
    if !usable(&bounds) {
        return None;
    }
    let c = prims.centroid(i);
    // Halves before adding: the plain midpoint overflows for boxes near the float range.
    let centroid = if c.is_finite() { c } else { 0.5 * bounds.min + 0.5 * bounds.max };
    Some(BuildPrim { bounds, centroid, index: i as u32 })
}

/// False for bounds that are empty or not finite: such a primitive can never be hit, and its box would
/// make every ancestor's box useless.
#[inline]
pub(super) fn usable(bounds: &Aabb) -> bool {
    !bounds.is_empty() && bounds.min.is_finite() && bounds.max.is_finite()
}

/// A leaf over `count` primitives at `offset`.
pub(super) fn make_leaf(bounds: Aabb, offset: usize, count: usize) -> BuildNode {
    debug_assert!((1..=LEAF_HARD_MAX).contains(&count));
    BuildNode::Leaf { bounds, first: offset as u32, count: count as u16 }
}

/// Appends `node`'s subtree depth first (first child right after its parent). The parts of the array
/// that the two children of an inner node take are known from their sizes, so they are written in
/// parallel.
pub(super) fn flatten(node: &BuildNode, out: &mut Vec<Node>) {
    let (start, len) = (out.len(), subtree_len(node));
    out.reserve(len);
    write(node, start as u32, &mut out.spare_capacity_mut()[..len]);
    // SAFETY: `write` wrote every entry of the `len` it was given (asserted for flat parts; leaves
    // and inner nodes take exactly their `subtree_len`).
    unsafe { out.set_len(start + len) };
}

/// The number of nodes of `node`'s subtree. Called on each level of the boxed top of the tree only.
fn subtree_len(node: &BuildNode) -> usize {
    match node {
        BuildNode::Leaf { .. } => 1,
        BuildNode::Inner { children, .. } => 1 + subtree_len(&children[0]) + subtree_len(&children[1]),
        BuildNode::Flat(nodes) => nodes.len(),
    }
}

/// Writes `node`'s subtree into `out`, all of it, as the nodes from index `base` on.
fn write(node: &BuildNode, base: u32, out: &mut [MaybeUninit<Node>]) {
    match node {
        BuildNode::Leaf { bounds, first, count } => {
            out[0].write(Node::leaf(*bounds, *first, *count));
        }
        BuildNode::Inner { bounds, axis, children } => {
            let (head, rest) = out.split_first_mut().expect("an inner node takes at least three nodes");
            let first = subtree_len(&children[0]);
            let (l, r) = rest.split_at_mut(first);
            head.write(Node::inner(*bounds, base + 1 + first as u32, *axis));
            rayon::join(|| write(&children[0], base + 1, l), || write(&children[1], base + 1 + first as u32, r));
        }
        BuildNode::Flat(nodes) => {
            assert_eq!(out.len(), nodes.len());
            for (o, n) in out.iter_mut().zip(nodes) {
                o.write(if n.is_leaf() { *n } else { Node { offset: n.offset + base, ..*n } });
            }
        }
    }
}
