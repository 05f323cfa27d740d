//! The collapse of a binary tree into the wide tree (what it produces: see the parent module). On one
//! thread, the depth-first walk of `walk.rs`; on more, three passes ([`parallel`]) that give the walk's
//! arrays byte for byte:
//!
//! 1. Plan ([`plan`]): every wide node's children (which binary nodes it lifts, which of its leaves
//!    get a lane per block: `choose.rs`, which the walk uses too), its numbers of inner children and of
//!    blocks, and the size of its subtree, in pre-order (the walk's order). A plan depends only on its
//!    binary subtree, so large subtrees are planned in parallel and concatenated in order.
//! 2. Place ([`place`]): the walk gives a node's inner children consecutive slots and appends its
//!    blocks when it reaches the node, so a node's first child slot and first block are prefix sums
//!    over the pre-order of those counts, and its own slot is its parent's first child slot plus its
//!    rank among its parent's inner children. One serial pass over the plans (a few per hundred
//!    triangles).
//! 3. Fill ([`fill`]): every wide node and its blocks independently, in parallel, the blocks into
//!    disjoint slices of the final array; the nodes come out in pre-order and are gathered into slot
//!    order (a copy of the node array, a fifth of the bytes the blocks take).
//!
//! The passes read the binary tree twice (plan, then fill) and copy the nodes once more, so one
//! thread keeps the walk. Cost: linear in the binary tree's size (plus a sort of each split leaf's few
//! triangles); the plans take 48 bytes per wide node.

use std::mem::MaybeUninit;

use rayon::prelude::*;

use super::choose::{make_block, plan_node, sort_leaf, Plan};
use super::{advise_huge_pages, LeafBlock, Node8, Ref};
use crate::accel::bvh::build::one_thread;
use crate::accel::bvh::Node;
use crate::geometry::TriangleMesh;
use crate::math::Aabb;

/// Binary subtrees of at least this many nodes plan their wide children in parallel: below it, a
/// task costs more than it saves.
pub(in crate::accel::bvh) const PLAN_PARALLEL: usize = 1 << 12;

/// Where a planned node and what it owns go in the final arrays.
#[derive(Debug, Clone, Copy, Default)]
struct Place {
    slot: u32,
    first_child: u32,
    first_block: u32,
}

/// The wide nodes (empty when the root is a leaf), the root and the blocks of `bin`, a non-empty
/// binary tree in depth-first layout whose leaves refer to `indices`.
pub(super) fn collapse(
    bin: &[Node],
    indices: &[u32],
    mesh: Option<&TriangleMesh>,
) -> (Vec<Node8>, Ref, Vec<LeafBlock>) {
    let root = &bin[0];
    if root.is_leaf() {
        let count = root.count as u32;
        let Some(mesh) = mesh else { return (Vec::new(), Ref { child: root.offset, count }, Vec::new()) };
        let ids = &indices[root.offset as usize..(root.offset + count) as usize];
        let blocks = ids.chunks(4).map(|c| make_block(mesh, c)).collect();
        return (Vec::new(), Ref { child: 0, count }, blocks);
    }
    let ctx = Ctx { bin, indices, mesh };
    let (nodes, blocks) = if one_thread() { super::walk::collapse(bin, indices, mesh) } else { parallel(&ctx) };
    (nodes, Ref { child: 0, count: 0 }, blocks)
}

/// On more threads: plan, place, fill (see the module documentation).
fn parallel(ctx: &Ctx) -> (Vec<Node8>, Vec<LeafBlock>) {
    let mut plans = Vec::new();
    plan(ctx.bin, ctx.mesh.is_some(), 0, true, &mut plans);
    let (places, n_nodes, n_blocks) = place(&plans);

    // Room made before the first write, so that neither array moves after its pages are advised.
    let mut blocks: Vec<LeafBlock> = Vec::with_capacity(n_blocks);
    advise_huge_pages(&blocks);
    let mut rest = &mut blocks.spare_capacity_mut()[..n_blocks];
    let parts: Vec<&mut [MaybeUninit<LeafBlock>]> = plans
        .iter()
        .map(|p| {
            let (part, tail) = std::mem::take(&mut rest).split_at_mut(p.blocks as usize);
            rest = tail;
            part
        })
        .collect();
    let mut pre = Vec::new();
    plans.par_iter().zip(&places).zip(parts).map(|((p, at), out)| fill(ctx, p, at, out)).collect_into_vec(&mut pre);
    // SAFETY: the parts tile the first `n_blocks` entries of the spare capacity, and `fill` returned
    // only after writing every entry of its part (it asserts so).
    unsafe { blocks.set_len(n_blocks) };

    let mut order = vec![0u32; n_nodes];
    for (r, at) in places.iter().enumerate() {
        order[at.slot as usize] = r as u32;
    }
    let mut nodes = Vec::with_capacity(n_nodes);
    advise_huge_pages(&nodes);
    order.par_iter().map(|&r| pre[r as usize]).collect_into_vec(&mut nodes);
    (nodes, blocks)
}

/// Appends the plans of the wide subtree whose root lifts binary inner node `i`, in pre-order.
/// `parallel`: the subtree may be large enough to plan its children's subtrees in parallel.
fn plan(bin: &[Node], mesh: bool, i: usize, parallel: bool, out: &mut Vec<Plan>) {
    let p = plan_node(bin, mesh, i);
    let at = out.len();
    out.push(p);
    let inner = p.kids[..p.n as usize].iter().map(|&c| c as usize).filter(|&c| !bin[c].is_leaf());
    if parallel && subtree_len(bin, i) >= PLAN_PARALLEL {
        let inner: Vec<usize> = inner.collect();
        let parts: Vec<Vec<Plan>> = inner
            .par_iter()
            .map(|&c| {
                let mut part = Vec::new();
                plan(bin, mesh, c, true, &mut part);
                part
            })
            .collect();
        for part in parts {
            out.extend_from_slice(&part);
        }
    } else {
        for c in inner {
            plan(bin, mesh, c, false, out);
        }
    }
    out[at].size = (out.len() - at) as u32;
}

/// The number of nodes of binary subtree `i` (depth first: it ends at its rightmost leaf).
fn subtree_len(bin: &[Node], i: usize) -> usize {
    let mut j = i;
    while !bin[j].is_leaf() {
        j = bin[j].offset as usize;
    }
    j + 1 - i
}

/// Each plan's place, the number of wide nodes and the number of blocks.
fn place(plans: &[Plan]) -> (Vec<Place>, usize, usize) {
    let mut places = vec![Place::default(); plans.len()];
    let (mut next_slot, mut next_block) = (1u32, 0u32);
    for (r, p) in plans.iter().enumerate() {
        let first_child = next_slot;
        places[r].first_child = first_child;
        places[r].first_block = next_block;
        next_slot += p.inner as u32;
        next_block += p.blocks;
        // The inner children's plans follow in pre-order, each after the subtree of the one before.
        let mut c = r + 1;
        for j in 0..p.inner as u32 {
            places[c].slot = first_child + j;
            c += plans[c].size as usize;
        }
    }
    (places, next_slot as usize, next_block as usize)
}

/// What [`fill`] reads.
struct Ctx<'a> {
    bin: &'a [Node],
    indices: &'a [u32],
    mesh: Option<&'a TriangleMesh>,
}

/// The wide node of plan `p` at `at`; writes every entry of `out`, the blocks of its leaves.
fn fill(ctx: &Ctx, p: &Plan, at: &Place, out: &mut [MaybeUninit<LeafBlock>]) -> Node8 {
    let mut node = Node8::EMPTY;
    let mut lane = 0;
    let mut put = |bounds: Aabb, r: Ref| {
        node.set_lane(lane, bounds, r);
        lane += 1;
    };
    let mut next_child = at.first_child;
    let mut written = 0;
    for (k, &c) in p.kids[..p.n as usize].iter().enumerate() {
        let b = &ctx.bin[c as usize];
        if !b.is_leaf() {
            put(b.bounds(), Ref { child: next_child, count: 0 });
            next_child += 1;
            continue;
        }
        let count = b.count as u32;
        let ids = &ctx.indices[b.offset as usize..(b.offset + count) as usize];
        let Some(mesh) = ctx.mesh else {
            put(b.bounds(), Ref { child: b.offset, count });
            continue;
        };
        if p.split & (1 << k) != 0 {
            let sorted = sort_leaf(b, ids, mesh);
            for chunk in sorted[..ids.len()].chunks(4) {
                let bounds = Aabb::from_points(chunk.iter().flat_map(|&i| mesh.triangle(i as usize)));
                out[written].write(make_block(mesh, chunk));
                put(bounds, Ref { child: at.first_block + written as u32, count: chunk.len() as u32 });
                written += 1;
            }
        } else {
            put(b.bounds(), Ref { child: at.first_block + written as u32, count });
            for chunk in ids.chunks(4) {
                out[written].write(make_block(mesh, chunk));
                written += 1;
            }
        }
    }
    assert_eq!(written, out.len(), "a plan's blocks are all written");
    node
}
