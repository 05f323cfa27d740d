//! Top-down octree build: a cell becomes a leaf ([`make_leaf`]) or is cut at its midpoint and its
//! references distributed to the eight octants ([`partition`]), the split being kept only when it pays
//! ([`split_pays`]); the temporary tree is then written depth first into the flat node array.
//!
//! Which cells reference a primitive: every octant, grown by a margin, that the primitive overlaps
//! ([`Primitives::overlaps_box`]: exact for triangles, conservative otherwise). The box is closed, so a
//! triangle lying on a split plane goes to both sides. The margin (2^-16 of the root, at least a few
//! ulps of the coordinates) covers the rounding of the watertight triangle test: it may report a hit a
//! hair outside the triangle, and that point must still lie in a cell that references the triangle,
//! or the octree and brute force would disagree. The error is a few ulps of the distances from the ray
//! origin, so the margin covers rays starting within ~64 scene sizes; it costs a handful of extra
//! references for primitives that nearly touch a cell.
//!
//! When to stop: at most `max_leaf_prims` references, `max_depth`, a cell too small to cut in `f32`, or
//! a split that does not pay. A split does not pay when every non-empty octant still holds all the
//! cell's references (coincident or cell-spanning primitives: splitting would only copy them), or
//! when its one-level surface area estimate, `2 * traversal_cost + sum(octant counts) / 4` (each octant
//! is hit by a quarter of the rays that hit its parent, two octants on average), is no better than the
//! leaf's `count`: cells full of large triangles would otherwise multiply references four-fold per
//! level. A lone octant holding everything (a small cluster in a big cell) is still split: the cluster
//! shrinks relative to the cells, and the path it follows is one cell per level.

use rayon::prelude::*;

use super::{can_split, child_box, grown, is_live, split_point, Node, OctreeParams, INNER};
use crate::accel::Primitives;
use crate::math::{Aabb, Vec3};

/// Cells with at least this many references are partitioned and built in parallel.
const PARALLEL_REFS: usize = 4096;

/// Relative size of the overlap margin; see the module docs.
const MARGIN: f32 = 1.0 / 65_536.0;

/// What the builder hands to [`super::Octree`].
pub(super) struct Built {
    pub nodes: Vec<Node>,
    pub refs: Vec<u32>,
    pub root: Aabb,
    pub bounds: Aabb,
    pub margin: f32,
}

/// The temporary tree.
enum Cell {
    Leaf(Vec<u32>),
    Inner(Vec<Cell>),
}

struct Ctx<'a, P: ?Sized> {
    prims: &'a P,
    /// Bounds of every primitive, computed once.
    bounds: Vec<Aabb>,
    params: OctreeParams,
    margin: f32,
}

/// Builds the octree over `prims`.
pub(super) fn build<P: Primitives + ?Sized>(prims: &P, params: &OctreeParams) -> Built {
    let bounds: Vec<Aabb> = (0..prims.len()).into_par_iter().map(|i| prims.bounds(i)).collect();
    let live: Vec<u32> = (0..prims.len() as u32).filter(|&i| is_live(&bounds[i as usize])).collect();
    let union = live.iter().fold(Aabb::EMPTY, |b, &i| b.union(bounds[i as usize]));
    if live.is_empty() {
        return Built { nodes: Vec::new(), refs: Vec::new(), root: Aabb::EMPTY, bounds: Aabb::EMPTY, margin: 0.0 };
    }
    let root = root_cube(&union);
    let side = root.extent().max_element();
    let coord = root.min.abs().max(root.max.abs()).max_element();
    // A few ulps of the coordinates (2^-21 = 4 ulps) so that the margin survives rounding far from 0.
    let margin = (side * MARGIN).max(coord / 2_097_152.0).max(f32::MIN_POSITIVE);
    let ctx = Ctx { prims, bounds, params: *params, margin };
    let tree = build_cell(&ctx, &root, live, 0);
    let mut nodes = vec![Node { offset: 0, count: 0 }];
    let mut refs = Vec::new();
    flatten(tree, 0, &mut nodes, &mut refs);
    Built { nodes, refs, root, bounds: union, margin }
}

/// The cube around `b`, centred on it, enlarged by 2^-10 of its size (and a few ulps) so that
/// primitives on the faces of `b` are strictly inside, and grown over `b` should rounding clip it.
fn root_cube(b: &Aabb) -> Aabb {
    let c = b.center();
    let half = 0.5 * b.extent().max_element();
    let pad = half / 1024.0 + c.abs().max_element() / 1_048_576.0 + f32::MIN_POSITIVE;
    let h = Vec3::splat(half + pad);
    Aabb::new(c - h, c + h).union(*b)
}

fn build_cell<P: Primitives + ?Sized>(ctx: &Ctx<'_, P>, cell: &Aabb, refs: Vec<u32>, depth: usize) -> Cell {
    if refs.len() <= ctx.params.max_leaf_prims || depth >= ctx.params.max_depth {
        return make_leaf(refs);
    }
    let mid = split_point(cell);
    if !can_split(cell, mid) {
        return make_leaf(refs);
    }
    let octants = partition(ctx, cell, mid, &refs);
    if !split_pays(&octants, refs.len(), ctx.params.traversal_cost) {
        return make_leaf(refs);
    }
    let parallel = refs.len() >= PARALLEL_REFS;
    drop(refs);
    let child = |(k, r): (usize, Vec<u32>)| build_cell(ctx, &child_box(cell, mid, k), r, depth + 1);
    let children = if parallel {
        octants.into_par_iter().enumerate().map(child).collect()
    } else {
        octants.into_iter().enumerate().map(child).collect()
    };
    Cell::Inner(children)
}

fn make_leaf(refs: Vec<u32>) -> Cell {
    Cell::Leaf(refs)
}

/// The references of each octant (grown by the margin), in ascending order.
fn partition<P: Primitives + ?Sized>(ctx: &Ctx<'_, P>, cell: &Aabb, mid: Vec3, refs: &[u32]) -> Vec<Vec<u32>> {
    let octant = |k: usize| {
        let b = grown(&child_box(cell, mid, k), ctx.margin);
        refs.iter().copied().filter(|&i| overlaps(ctx, i as usize, &b)).collect::<Vec<u32>>()
    };
    if refs.len() >= PARALLEL_REFS {
        (0..8).into_par_iter().map(octant).collect()
    } else {
        (0..8).map(octant).collect()
    }
}

/// Whether primitive `i` goes into the (grown) cell `b`.
#[inline]
fn overlaps<P: Primitives + ?Sized>(ctx: &Ctx<'_, P>, i: usize, b: &Aabb) -> bool {
    goes_into(ctx.prims, i, &ctx.bounds[i], b)
}

/// Whether primitive `i`, of bounds `pb`, goes into the grown cell `b`: bounds first, the exact test
/// only for primitives that straddle the cell's faces.
#[inline]
fn goes_into<P: Primitives + ?Sized>(prims: &P, i: usize, pb: &Aabb, b: &Aabb) -> bool {
    pb.overlaps(b) && (b.contains(pb) || prims.overlaps_box(i, b))
}

/// Whether cutting a cell of `count` references into `octants` is worth it; see the module docs.
fn split_pays(octants: &[Vec<u32>], count: usize, traversal_cost: f32) -> bool {
    let nonempty: Vec<usize> = octants.iter().map(Vec::len).filter(|&n| n > 0).collect();
    if nonempty.len() > 1 && nonempty.iter().all(|&n| n == count) {
        return false;
    }
    let sum: usize = octants.iter().map(Vec::len).sum();
    2.0 * f64::from(traversal_cost) + sum as f64 / 4.0 < count as f64
}

/// Writes `cell` into `nodes[slot]`, its children as eight consecutive nodes after everything so far.
fn flatten(cell: Cell, slot: usize, nodes: &mut Vec<Node>, refs: &mut Vec<u32>) {
    match cell {
        Cell::Leaf(r) => {
            nodes[slot] = Node { offset: refs.len() as u32, count: r.len() as u32 };
            refs.extend(r);
        }
        Cell::Inner(children) => {
            let first = nodes.len();
            nodes[slot] = Node { offset: first as u32, count: INNER };
            nodes.resize(first + 8, Node { offset: 0, count: 0 });
            for (k, c) in children.into_iter().enumerate() {
                flatten(c, first + k, nodes, refs);
            }
        }
    }
}

/// The build's test for primitive `i` and `cell` (grown by `margin`), for `validate`.
pub(super) fn references<P: Primitives + ?Sized>(prims: &P, i: usize, cell: &Aabb, margin: f32) -> bool {
    goes_into(prims, i, &prims.bounds(i), &grown(cell, margin))
}
