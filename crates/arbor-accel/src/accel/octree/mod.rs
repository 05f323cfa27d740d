//! Octree: the scene's bounding cube split into eight equal octants, recursively, with every primitive
//! referenced by every cell it truly overlaps (exact triangle-box overlap for triangles, Akenine-Möller
//! 2001; see `geometry::triangle_box`). Traversal visits the cells a ray crosses front to back and stops
//! once the closest hit lies inside the current cell (Glassner 1984, "Space subdivision for fast ray
//! tracing"; Revelles et al. 2000 order the children parametrically, here the at most four children a
//! ray crosses are simply sorted by entry distance). Closest-point queries visit cells nearest first
//! (`nearest.rs`).
//!
//! Layout: one flat array of 8-byte [`Node`]s; an inner node stores the index of the first of its eight
//! consecutive children (octant `k` has bit `a` of `k` set when it is the upper half on axis `a`), a
//! leaf a range of [`Octree::refs`]. Cell boxes are not stored: a child's box is its parent's cut at the
//! midpoint (`split_point`), computed the same way by the builder, the traversal and the checks, so
//! neighbouring cells share bit-identical faces.
//!
//! Invariants (checked by [`Accel::validate`], which the factory runs in debug builds):
//! - the root cube encloses every primitive with finite, non-empty bounds ("live"); the others can never
//!   be hit and are referenced nowhere;
//! - every inner cell has an interior split point, so its eight children tile it;
//! - a leaf references, in ascending order and once each, exactly the live primitives that overlap its
//!   cell grown by [`Octree::margin`] (see `build.rs` for why the margin);
//! - the tree is at most [`MAX_DEPTH`] deep, which sizes the traversal stack.
//!
//! Cost: the build tests each reference against the eight children at every level, O(refs x depth);
//! large cells are partitioned and their children built in parallel, with a result independent of the
//! thread count. A query visits the cells along the ray up to the closest hit. Memory: 8 bytes per node
//! plus 4 per reference; references per primitive grow with the primitives' size relative to the leaf
//! cells (about 5 on the 70k-triangle Stanford bunny with the defaults, 3.5 with `fast_build`).

mod build;
mod nearest;
mod traverse;
mod validate;

use std::time::{Duration, Instant};

use super::params::{ParamRange, ParamSet, ParamSpec, ParamValue};
use super::stats::StatsTally;
use super::{Accel, AccelStats, Hit, Nearest, Primitives, TraversalCounts};
use crate::math::{Aabb, DVec3, Ray, Vec3};

/// Deepest level any parameters can ask for (cells 1/65536 of the root): sizes the traversal stack.
pub const MAX_DEPTH: usize = 16;

/// `count` of an inner node.
const INNER: u32 = u32::MAX;

/// One node of the flat array.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(C)]
pub struct Node {
    /// Inner node: index of its first child (eight consecutive nodes). Leaf: offset of its first
    /// reference in [`Octree::refs`].
    pub offset: u32,
    /// Number of references of a leaf (0 for an empty cell); `u32::MAX` marks an inner node.
    pub count: u32,
}

const _: () = assert!(std::mem::size_of::<Node>() == 8);

impl Node {
    /// True for a leaf.
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.count != INNER
    }
    /// The leaf's range of references.
    #[inline]
    fn range(&self) -> std::ops::Range<usize> {
        self.offset as usize..self.offset as usize + self.count as usize
    }
}

/// The point where a cell is cut into octants. `0.5 * min + 0.5 * max` cannot overflow, and it lies in
/// `[min, max]`; when it equals either (a cell a few ulps wide) the cell cannot be split.
#[inline]
pub(crate) fn split_point(b: &Aabb) -> Vec3 {
    0.5 * b.min + 0.5 * b.max
}

/// True when `mid` is strictly inside `b` on every axis, so that the eight octants tile `b`.
#[inline]
fn can_split(b: &Aabb, mid: Vec3) -> bool {
    b.min.cmplt(mid).all() && mid.cmplt(b.max).all()
}

/// Octant `k` of `b` cut at `mid`.
#[inline]
fn child_box(b: &Aabb, mid: Vec3, k: usize) -> Aabb {
    let mut c = Aabb::new(b.min, mid);
    for a in 0..3 {
        if k & (1 << a) != 0 {
            c.min[a] = mid[a];
            c.max[a] = b.max[a];
        }
    }
    c
}

/// `b` grown by `m` on every side.
#[inline]
fn grown(b: &Aabb, m: f32) -> Aabb {
    Aabb::new(b.min - Vec3::splat(m), b.max + Vec3::splat(m))
}

/// True for bounds a primitive can be hit within.
#[inline]
fn is_live(b: &Aabb) -> bool {
    !b.is_empty() && b.min.is_finite() && b.max.is_finite()
}

/// Build knobs of the octree.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OctreeParams {
    /// A cell with at most this many references is a leaf. Valid: `>= 1`; the builder clamps values set
    /// directly.
    pub max_leaf_prims: usize,
    /// Deepest level (the root is level 0). Valid: `0..=16` ([`MAX_DEPTH`]); the builder clamps values
    /// set directly.
    pub max_depth: usize,
    /// Cost of visiting a cell relative to a primitive test, for the check that a split pays (it stops
    /// cells full of large primitives from multiplying references). Valid: finite, `>= 0`.
    pub traversal_cost: f32,
}

impl Default for OctreeParams {
    /// Leaves of up to 8 (the usual octree compromise: a primitive test is cheap next to a cell step,
    /// and smaller leaves multiply references), depth 10 (cells 1/1024 of the scene: a 100k-triangle
    /// mesh settles around depth 7-8, and deeper trees mostly serve dense clusters), and a cell visit
    /// as costly as a primitive test.
    fn default() -> Self {
        OctreeParams { max_leaf_prims: 8, max_depth: 10, traversal_cost: 1.0 }
    }
}

impl OctreeParams {
    /// Larger leaves, shallower tree: a quicker build, fewer references.
    pub fn fast_build() -> Self {
        OctreeParams { max_leaf_prims: 16, max_depth: 8, ..Self::default() }
    }
    /// Smaller leaves, deeper tree: fewer primitive tests per ray, more memory.
    pub fn quality() -> Self {
        OctreeParams { max_leaf_prims: 4, max_depth: 12, ..Self::default() }
    }
    /// Every field in range (a NaN or negative cost becomes the default).
    fn sanitized(&self) -> Self {
        let cost = self.traversal_cost;
        OctreeParams {
            max_leaf_prims: self.max_leaf_prims.max(1),
            max_depth: self.max_depth.min(MAX_DEPTH),
            traversal_cost: if cost.is_finite() && cost >= 0.0 { cost } else { Self::default().traversal_cost },
        }
    }
}

impl OctreeParams {
    /// The parameters by key, with their ranges.
    pub const PARAMS: &'static [ParamSpec] = &[
        ParamSpec {
            key: "leaf",
            about: "a cell with at most this many primitives is a leaf",
            range: ParamRange::Int { min: 1, max: None },
        },
        ParamSpec {
            key: "depth",
            about: "deepest level (the root is level 0)",
            range: ParamRange::Int { min: 0, max: Some(MAX_DEPTH as i64) },
        },
        ParamSpec {
            key: "traversal-cost",
            about: "cost of a cell visit relative to a primitive test",
            range: ParamRange::Float { min: 0.0, max: None },
        },
    ];
}

impl ParamSet for OctreeParams {
    fn specs(&self) -> &'static [ParamSpec] {
        Self::PARAMS
    }
    fn get(&self, key: &str) -> Option<ParamValue> {
        Some(match key {
            "leaf" => ParamValue::count(self.max_leaf_prims),
            "depth" => ParamValue::count(self.max_depth),
            "traversal-cost" => ParamValue::Float(self.traversal_cost.into()),
            _ => return None,
        })
    }
    fn put(&mut self, key: &str, v: ParamValue) {
        match key {
            "leaf" => self.max_leaf_prims = v.as_usize(),
            "depth" => self.max_depth = v.as_usize(),
            "traversal-cost" => self.traversal_cost = v.as_f32(),
            _ => {}
        }
    }
}

/// An octree over primitive indices.
#[derive(Debug, Clone)]
pub struct Octree {
    nodes: Vec<Node>,
    refs: Vec<u32>,
    /// The root cell (a cube, up to rounding); empty when nothing can be hit.
    root: Aabb,
    /// Union of the live primitives' bounds.
    bounds: Aabb,
    /// How much cells are grown for the overlap test of the build.
    margin: f32,
    len: usize,
    stats: AccelStats,
}

impl Octree {
    /// Builds an octree over `prims`.
    pub fn build<P: Primitives + ?Sized>(prims: &P, params: &OctreeParams) -> Self {
        let start = Instant::now();
        let built = build::build(prims, &params.sanitized());
        let mut tree = Octree {
            nodes: built.nodes,
            refs: built.refs,
            root: built.root,
            bounds: built.bounds,
            margin: built.margin,
            len: prims.len(),
            stats: AccelStats::default(),
        };
        tree.stats = tree.compute_stats(start.elapsed());
        tree
    }

    /// The flat node array; node 0 is the root (empty when no primitive can be hit).
    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// Primitive references; leaves refer to ranges of it.
    pub fn refs(&self) -> &[u32] {
        &self.refs
    }

    /// The root cell.
    pub fn root(&self) -> Aabb {
        self.root
    }

    /// How far beyond its cell a primitive may lie and still be referenced there: a small fraction of
    /// the root (see `build.rs`).
    pub fn margin(&self) -> f32 {
        self.margin
    }

    /// Calls `f(node, cell, depth)` for every node, depth first.
    fn for_each_cell(&self, mut f: impl FnMut(&Node, &Aabb, usize)) {
        let mut stack = if self.nodes.is_empty() { vec![] } else { vec![(0usize, self.root, 0usize)] };
        while let Some((i, cell, depth)) = stack.pop() {
            let node = &self.nodes[i];
            f(node, &cell, depth);
            if !node.is_leaf() {
                let mid = split_point(&cell);
                for k in (0..8).rev() {
                    stack.push((node.offset as usize + k, child_box(&cell, mid, k), depth + 1));
                }
            }
        }
    }

    fn compute_stats(&self, build_time: Duration) -> AccelStats {
        let bytes = std::mem::size_of::<Self>()
            + self.nodes.len() * std::mem::size_of::<Node>()
            + self.refs.len() * std::mem::size_of::<u32>();
        let mut tally = StatsTally::new("octree", self.len, self.nodes.len(), bytes, build_time);
        // Octants have a quarter of their parent's area, so a cell at depth `d` is hit by a fraction
        // 4^-d of the rays that hit the root.
        self.for_each_cell(|node, _, depth| {
            let p = 0.25f64.powi(depth as i32);
            if node.is_leaf() {
                tally.leaf(depth, node.count as usize, p);
            } else {
                tally.inner(p);
            }
        });
        tally.finish()
    }
}

impl<P: Primitives + ?Sized> Accel<P> for Octree {
    fn bounds(&self) -> Aabb {
        self.bounds
    }

    fn intersect(&self, prims: &P, ray: &Ray, t_max: f32) -> Option<Hit> {
        traverse::traverse::<P, false, false>(self, prims, ray, t_max, &mut TraversalCounts::default())
    }

    fn intersect_counted(&self, prims: &P, ray: &Ray, t_max: f32, counts: &mut TraversalCounts) -> Option<Hit> {
        traverse::traverse::<P, true, false>(self, prims, ray, t_max, counts)
    }

    fn occluded(&self, prims: &P, ray: &Ray, t_max: f32) -> bool {
        traverse::traverse::<P, false, true>(self, prims, ray, t_max, &mut TraversalCounts::default()).is_some()
    }

    fn closest_point(&self, prims: &P, p: DVec3, max_dist2: f64) -> Option<Nearest> {
        let slack = crate::accel::nearest::slack(&self.bounds);
        crate::accel::nearest::query(p, max_dist2, slack, |best| nearest::walk(self, prims, best))
    }

    fn stats(&self) -> AccelStats {
        self.stats.clone()
    }

    fn validate(&self, prims: &P) -> Result<(), String> {
        validate::validate(self, prims)
    }

    /// The cells at `depth`, leaving out empty leaves (regions holding nothing).
    fn boxes_at_depth(&self, _: &P, depth: usize) -> Vec<Aabb> {
        let mut out = Vec::new();
        self.for_each_cell(|node, cell, d| {
            if d == depth && !(node.is_leaf() && node.count == 0) {
                out.push(*cell);
            }
        });
        out
    }
}

#[cfg(test)]
mod tests;
