//! Kd-tree with surface-area-heuristic splits, built in O(N log N) by the sorted-event sweep of Wald and
//! Havran ("On building fast kd-trees for ray tracing, and on doing that in O(N log N)", RT 2006), with
//! "perfect splits" (candidates from primitive bounds clipped to the node), traversal and intersection
//! costs, an empty-space bonus and automatic termination; stored as pbrt's 8-byte `KdAccelNode`s and
//! traversed front to back with a t-interval (pbrt-v4's `KdTreeAggregate::Intersect`); closest-point
//! queries walk it nearest cell first (`nearest.rs`).
//!
//! Layout: nodes are written depth first, so an inner node's "below" child (the side of smaller
//! coordinates) is the next node and only the "above" child's index is stored. A leaf of one primitive
//! holds its index inline; larger leaves hold a range of [`KdTree::prim_refs`], where a primitive that
//! straddles splits appears once per leaf it touches.
//!
//! Invariants checked by [`Accel::validate`], which the factory runs in debug builds:
//! - every reference is a primitive index in range, and every primitive with finite, non-empty bounds
//!   is referenced at least once; the others can never be hit and are left out;
//! - every leaf's primitives have bounds that overlap the leaf's box;
//! - each split lies strictly inside its node's box; the tree is less than [`MAX_DEPTH`] deep, which sizes
//!   the traversal stack.
//!
//! And by construction: a primitive is in every leaf whose (closed) box holds a point of it, because
//! its clipped bounds ([`Primitives::clipped_bounds`]) are conservative; that, not the SAH, is what
//! makes traversal exact.
//!
//! Termination: a node is a leaf when no split beats the leaf's SAH cost, at pbrt's depth limit
//! `round(8 + 1.3 log2 N)` (at most [`MAX_DEPTH`] - 1), or when its split would be the fourth bad refine
//! on its path: a split with both sides non-empty whose sides hold more than 1.5 n of its n
//! primitives. That bounds the duplication: weighting each node's count by 2^-(bad refines above it),
//! the weighted sum per depth grows by at most 3/2 per level, so the references at depth d total at
//! most 2^3 (3/2)^d N, and there are at most as many inner nodes there. Without the limit, overlapping
//! flat primitives in one plane (where a split always looks slightly cheaper and copies nearly every
//! primitive) give up to 2^d.
//!
//! Cost: the build sorts the events once (O(N log N)) and then does O(n) work per node (sweep,
//! classification, a linear merge) plus a sort of the new events of the primitives straddling the
//! split: O(N log N) overall under the paper's assumption that O(sqrt n) primitives straddle a node's
//! split (the full algorithm, not the O(N log² N) sort-per-node variant). Unlike the paper, which keeps
//! one list for all three axes, the events are kept in one list per axis; the work is the same. The
//! build is single-threaded and deterministic. Memory: 8 bytes per node, 4 per reference of leaves of
//! two or more. Queries are O(log N) on typical scenes.

mod build;
mod nearest;
mod traverse;

#[cfg(test)]
mod tests;

use std::time::{Duration, Instant};

use super::params::{ParamRange, ParamSet, ParamSpec, ParamValue};
use super::stats::StatsTally;
use super::{Accel, AccelStats, Hit, Nearest, Primitives, TraversalCounts};
use crate::math::{Aabb, DVec3, Ray};

/// Hard limit on the depth of any leaf, whatever the parameters; sizes the traversal stack.
pub const MAX_DEPTH: usize = 64;

/// Flag value of a leaf in [`Node::flags`]'s low two bits (0, 1, 2 are split axes).
const LEAF: u32 = 3;

/// One node of the flat array: pbrt's `KdAccelNode`, 8 bytes.
///
/// `flags`' low two bits are the split axis (0, 1, 2) or `LEAF` (3); the upper 30 bits are the above
/// child's index (inner node) or the primitive count (leaf). `data` is the split position's bits (inner
/// node), the primitive itself (leaf of one) or the offset of the first reference (larger leaf).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(C)]
pub struct Node {
    data: u32,
    flags: u32,
}

const _: () = assert!(std::mem::size_of::<Node>() == 8);

impl Node {
    /// An inner node splitting `axis` at `split`, whose above child is node `above`.
    pub fn inner(axis: usize, split: f32, above: u32) -> Self {
        debug_assert!(axis < 3 && above < (1 << 30));
        Node { data: split.to_bits(), flags: (above << 2) | axis as u32 }
    }
    /// A leaf of `count` primitives: the primitive itself when `count` is 1, else the offset of the
    /// first of its references.
    pub fn leaf(count: u32, data: u32) -> Self {
        debug_assert!(count < (1 << 30));
        Node { data, flags: (count << 2) | LEAF }
    }
    /// True for a leaf.
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.flags & 3 == LEAF
    }
    /// Split axis of an inner node.
    #[inline]
    pub fn axis(&self) -> usize {
        (self.flags & 3) as usize
    }
    /// Split position of an inner node.
    #[inline]
    pub fn split(&self) -> f32 {
        f32::from_bits(self.data)
    }
    /// Index of an inner node's above child (the below child is the next node).
    #[inline]
    pub fn above(&self) -> usize {
        (self.flags >> 2) as usize
    }
    /// Number of primitives in a leaf.
    #[inline]
    pub fn count(&self) -> usize {
        (self.flags >> 2) as usize
    }
    /// The same node in a subtree moved to start at node `node_base` with its references at `ref_base`
    /// (a subtree built apart, then appended).
    pub(super) fn relocated(self, node_base: u32, ref_base: u32) -> Self {
        if !self.is_leaf() {
            Node::inner(self.axis(), self.split(), self.above() as u32 + node_base)
        } else if self.count() >= 2 {
            Node::leaf(self.count() as u32, self.data + ref_base)
        } else {
            self
        }
    }
    /// A leaf's primitives, resolved against the reference array.
    #[inline]
    pub fn prims<'a>(&'a self, refs: &'a [u32]) -> &'a [u32] {
        match self.count() {
            0 => &[],
            1 => std::slice::from_ref(&self.data),
            n => &refs[self.data as usize..self.data as usize + n],
        }
    }
}

/// Build knobs of the kd-tree (costs in the units of Wald and Havran's SAH).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KdTreeParams {
    /// Cost of one traversal step (`K_T`). Valid: finite, `>= 0`.
    pub traversal_cost: f32,
    /// Cost of one primitive test (`K_I`). Valid: finite, `>= 0`.
    pub intersection_cost: f32,
    /// Fraction of the cost taken off a split that leaves one side empty (Wald and Havran use 0.2:
    /// factor 0.8), which favours cutting off empty space. Valid: `0..=1`.
    pub empty_bonus: f32,
    /// Deepest level; `None` is pbrt's `8 + 1.3 log2 N`. Valid: `0..=63` (`MAX_DEPTH - 1`); the
    /// builder clamps values set directly.
    pub max_depth: Option<usize>,
}

impl Default for KdTreeParams {
    /// `K_T = 30`, `K_I = 20`, bonus 0.2 and pbrt's automatic depth. Wald and Havran's `K_T = 15`
    /// ([`KdTreeParams::wald_havran`]) builds trees about twice as large that traced slower
    /// (docs/performance.md).
    fn default() -> Self {
        KdTreeParams { traversal_cost: 30.0, intersection_cost: 20.0, empty_bonus: 0.2, max_depth: None }
    }
}

impl KdTreeParams {
    /// The costs of Wald and Havran's paper: `K_T = 15`, `K_I = 20`, bonus 0.2.
    pub fn wald_havran() -> Self {
        KdTreeParams { traversal_cost: 15.0, ..Self::default() }
    }
    /// pbrt's `KdTreeAggregate` costs: traversal 1, intersection 80, empty bonus 0.5.
    pub fn pbrt() -> Self {
        KdTreeParams { traversal_cost: 1.0, intersection_cost: 80.0, empty_bonus: 0.5, max_depth: None }
    }
    /// Costlier traversal: on the bunny, a tree of 2.5 references per triangle instead of 3.6, built
    /// in about two thirds of the time, tracing at nearly the same speed.
    pub fn fast_build() -> Self {
        KdTreeParams { traversal_cost: 60.0, ..Self::default() }
    }
    /// The parameters with every field in range (NaN or negative costs become the defaults), and the
    /// depth limit resolved for `n` primitives.
    fn sanitized(&self, n: usize) -> (Self, usize) {
        let d = Self::default();
        let cost = |c: f32, dflt: f32| if c.is_finite() && c >= 0.0 { c } else { dflt };
        let auto = (8.0 + 1.3 * (n.max(1) as f64).log2()).round() as usize;
        let depth = self.max_depth.unwrap_or(auto).min(MAX_DEPTH - 1);
        let bonus = if self.empty_bonus.is_finite() { self.empty_bonus.clamp(0.0, 1.0) } else { d.empty_bonus };
        let p = KdTreeParams {
            traversal_cost: cost(self.traversal_cost, d.traversal_cost),
            intersection_cost: cost(self.intersection_cost, d.intersection_cost),
            empty_bonus: bonus,
            max_depth: Some(depth),
        };
        (p, depth)
    }
}

impl KdTreeParams {
    /// The parameters by key, with their ranges.
    pub const PARAMS: &'static [ParamSpec] = &[
        ParamSpec {
            key: "traversal-cost",
            about: "cost of a traversal step (K_T)",
            range: ParamRange::Float { min: 0.0, max: None },
        },
        ParamSpec {
            key: "intersection-cost",
            about: "cost of a primitive test (K_I)",
            range: ParamRange::Float { min: 0.0, max: None },
        },
        ParamSpec {
            key: "empty-bonus",
            about: "share of the cost taken off splits with an empty side",
            range: ParamRange::Float { min: 0.0, max: Some(1.0) },
        },
        ParamSpec {
            key: "depth",
            about: "deepest level (auto: 8 + 1.3 log2 N)",
            range: ParamRange::IntOrAuto { min: 0, max: MAX_DEPTH as i64 - 1 },
        },
    ];
}

impl ParamSet for KdTreeParams {
    fn specs(&self) -> &'static [ParamSpec] {
        Self::PARAMS
    }
    fn get(&self, key: &str) -> Option<ParamValue> {
        Some(match key {
            "traversal-cost" => ParamValue::Float(self.traversal_cost.into()),
            "intersection-cost" => ParamValue::Float(self.intersection_cost.into()),
            "empty-bonus" => ParamValue::Float(self.empty_bonus.into()),
            "depth" => self.max_depth.map_or(ParamValue::Auto, ParamValue::count),
            _ => return None,
        })
    }
    fn put(&mut self, key: &str, v: ParamValue) {
        match key {
            "traversal-cost" => self.traversal_cost = v.as_f32(),
            "intersection-cost" => self.intersection_cost = v.as_f32(),
            "empty-bonus" => self.empty_bonus = v.as_f32(),
            "depth" => self.max_depth = (v != ParamValue::Auto).then(|| v.as_usize()),
            _ => {}
        }
    }
}

/// A kd-tree over primitive indices.
#[derive(Debug, Clone)]
pub struct KdTree {
    nodes: Vec<Node>,
    refs: Vec<u32>,
    bounds: Aabb,
    len: usize,
    stats: AccelStats,
}

impl KdTree {
    /// Builds a kd-tree over `prims` (deterministic: the result depends only on the input).
    pub fn build<P: Primitives + ?Sized>(prims: &P, params: &KdTreeParams) -> KdTree {
        let start = Instant::now();
        let (params, depth) = params.sanitized(prims.len());
        let (nodes, refs, bounds) = build::build(prims, &params, depth);
        let mut tree = KdTree { nodes, refs, bounds, len: prims.len(), stats: AccelStats::default() };
        tree.stats = tree.compute_stats(start.elapsed());
        tree
    }

    /// The flat node array; node 0 is the root (empty when no primitive can be hit).
    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// Primitive references of the leaves with more than one primitive.
    pub fn prim_refs(&self) -> &[u32] {
        &self.refs
    }

    /// Visits every node depth first with its index, box and depth. Child links that point backwards
    /// or out of the array are not followed (validation reports them), so the walk always ends.
    fn walk(&self, mut f: impl FnMut(usize, &Node, &Aabb, usize)) {
        let mut stack = if self.nodes.is_empty() { vec![] } else { vec![(0usize, self.bounds, 0usize)] };
        while let Some((i, b, depth)) = stack.pop() {
            let n = &self.nodes[i];
            f(i, n, &b, depth);
            if !n.is_leaf() && i + 1 < n.above() && n.above() < self.nodes.len() {
                let (below, above) = split_box(&b, n.axis(), n.split());
                stack.push((n.above(), above, depth + 1));
                stack.push((i + 1, below, depth + 1));
            }
        }
    }

    fn compute_stats(&self, build_time: Duration) -> AccelStats {
        let bytes = std::mem::size_of::<Self>()
            + self.nodes.len() * std::mem::size_of::<Node>()
            + self.refs.len() * std::mem::size_of::<u32>();
        let mut tally = StatsTally::new("kdtree", self.len, self.nodes.len(), bytes, build_time);
        let root_area = self.bounds.area_f64();
        self.walk(|_, n, b, depth| {
            // A flat or degenerate root makes every node equally likely to be visited.
            let p = if root_area > 0.0 { b.area_f64() / root_area } else { 1.0 };
            if n.is_leaf() {
                tally.leaf(depth, n.count(), p);
            } else {
                tally.inner(p);
            }
        });
        tally.finish()
    }

    /// Checks the invariants listed in the module docs.
    fn check(&self, prims: &impl Fn(usize) -> Aabb, n: usize) -> Result<(), String> {
        let mut seen = vec![false; n];
        let mut err = None;
        let mut visited = 0usize;
        self.walk(|i, node, b, depth| {
            visited += 1;
            if err.is_some() {
                return;
            }
            if depth >= MAX_DEPTH {
                err = Some(format!("a node at depth {depth} would overflow the traversal stack"));
            } else if node.is_leaf() {
                if node.count() > 1 && node.data as usize + node.count() > self.refs.len() {
                    err = Some(format!("a leaf refers past the {} references", self.refs.len()));
                    return;
                }
                for &p in node.prims(&self.refs) {
                    match seen.get_mut(p as usize) {
                        None => err = Some(format!("primitive index {p} out of range")),
                        Some(s) => *s = true,
                    }
                    if !prims(p as usize).overlaps(b) {
                        err = Some(format!("primitive {p} is in a leaf its bounds do not reach"));
                    }
                }
            } else {
                let (a, s) = (node.axis(), node.split());
                if !(b.min[a] < s && s < b.max[a]) {
                    err = Some(format!("split {s} on axis {a} is not inside its node {b:?}"));
                } else if node.above() <= i + 1 || node.above() >= self.nodes.len() {
                    err = Some(format!("inner node {i} has above child {}", node.above()));
                }
            }
        });
        if let Some(e) = err {
            return Err(e);
        }
        if visited != self.nodes.len() {
            return Err(format!("{visited} of {} nodes are reachable", self.nodes.len()));
        }
        for (i, s) in seen.iter().enumerate() {
            let b = prims(i);
            if !s && build::is_live(&b) {
                return Err(format!("primitive {i} has finite bounds but is in no leaf"));
            }
        }
        Ok(())
    }
}

/// The boxes below and above `split` on `axis`.
fn split_box(b: &Aabb, axis: usize, split: f32) -> (Aabb, Aabb) {
    let (mut below, mut above) = (*b, *b);
    below.max[axis] = split;
    above.min[axis] = split;
    (below, above)
}

impl<P: Primitives + ?Sized> Accel<P> for KdTree {
    fn bounds(&self) -> Aabb {
        self.bounds
    }

    fn intersect(&self, prims: &P, ray: &Ray, t_max: f32) -> Option<Hit> {
        traverse::intersect::<P, false>(self, prims, ray, t_max, &mut TraversalCounts::default())
    }

    fn intersect_counted(&self, prims: &P, ray: &Ray, t_max: f32, counts: &mut TraversalCounts) -> Option<Hit> {
        traverse::intersect::<P, true>(self, prims, ray, t_max, counts)
    }

    fn occluded(&self, prims: &P, ray: &Ray, t_max: f32) -> bool {
        traverse::occluded(self, prims, ray, t_max)
    }

    fn closest_point(&self, prims: &P, p: DVec3, max_dist2: f64) -> Option<Nearest> {
        let slack = crate::accel::nearest::slack(&self.bounds);
        crate::accel::nearest::query(p, max_dist2, slack, |best| nearest::walk(self, prims, best))
    }

    fn stats(&self) -> AccelStats {
        self.stats.clone()
    }

    fn validate(&self, prims: &P) -> Result<(), String> {
        if self.len != prims.len() {
            return Err(format!("built over {} primitives, queried with {}", self.len, prims.len()));
        }
        self.check(&|i| prims.bounds(i), prims.len())
    }

    fn boxes_at_depth(&self, _: &P, depth: usize) -> Vec<Aabb> {
        let mut out = Vec::new();
        self.walk(|_, _, b, d| {
            if d == depth {
                out.push(*b);
            }
        });
        out
    }
}
