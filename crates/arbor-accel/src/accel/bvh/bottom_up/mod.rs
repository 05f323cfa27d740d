//! Bottom-up (agglomerative) BVH construction: start from one cluster per primitive and repeatedly
//! merge two clusters into a new node, until one cluster, the root, is left. Two methods:
//!
//! - [`greedy`]: the exact greedy method (Walter et al. 2008, "Fast agglomerative clustering for
//!   rendering", its exact baseline): always merge the pair of least cost over all pairs. O(n) memory,
//!   O(n²) time in practice, O(n³) worst case; for small inputs.
//! - [`ploc`]: Parallel Locally-Ordered Clustering (Meister and Bittner 2018, "Parallel locally-ordered
//!   clustering for bounding volume hierarchy construction"): clusters sorted along a Morton curve each
//!   look for their nearest neighbour within a small window, mutual nearest neighbours merge. O(n log n)
//!   for the sort, O(n · radius) per iteration.
//!
//! Both produce a binary tree of single-primitive leaves in an arena ([`Cluster`]). [`emit`] then
//! collapses subtrees into leaves where the surface area heuristic says it pays, keeps the depth below
//! [`super::MAX_DEPTH`] (rebalancing too-deep subtrees with the median split), and writes the same flat
//! nodes as the top-down builders, so the BVH's traversal and checks are reused unchanged.
//!
//! Every step is deterministic (ties are broken by position), so the tree does not depend on the
//! thread count. Primitives with empty or non-finite bounds are kept out of the tree as in `build.rs`.

mod emit;
mod greedy;
mod ploc;

#[cfg(test)]
mod tests;

use super::build::{finish, split_live};
use super::{Node, LEAF_HARD_MAX};
use crate::accel::params::{ParamRange, ParamSet, ParamSpec, ParamValue};
use crate::accel::Primitives;
use crate::math::Aabb;

/// Which agglomerative method builds the tree.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BottomUpMethod {
    /// [`BottomUpMethod::Greedy`] up to [`BottomUpParams::greedy_max`] primitives, [`BottomUpMethod::Ploc`] above.
    Auto,
    /// The exact greedy method: O(n²) time in practice, O(n³) worst case, whatever the input size
    /// (`greedy-max` applies to `auto` only).
    Greedy,
    /// PLOC (Meister and Bittner 2018): O(n log n).
    Ploc,
}

/// The cost of merging two clusters, which the greedy method minimises at every step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MergeCost {
    /// Distance between the centres of the two clusters' boxes.
    Distance,
    /// Volume of the merged box.
    Volume,
    /// Surface area of the merged box (Walter et al. 2008; what PLOC always uses).
    Area,
}

/// Build knobs of the bottom-up BVH.
#[derive(Debug, Clone, PartialEq)]
pub struct BottomUpParams {
    /// Greedy, PLOC, or greedy for small inputs.
    pub method: BottomUpMethod,
    /// The greedy method's merge cost ("growth" is measured by the merged box itself rather than by
    /// its excess over the two parts: the excess lets a large cluster absorb its small neighbours one by
    /// one, which builds chains).
    pub cost: MergeCost,
    /// PLOC's search radius: each cluster looks this many positions either way along the Morton order.
    /// Valid: `1..=256`; the builder clamps values set directly.
    pub radius: usize,
    /// [`BottomUpMethod::Auto`] uses the greedy method up to this many primitives.
    pub greedy_max: usize,
    /// Subtrees of at most this many primitives become one leaf when the SAH cost of the leaf (with
    /// [`super::BvhParams`]' default costs) is not above the subtree's; 1 keeps one primitive per leaf.
    /// Valid: `1..=64` (`LEAF_HARD_MAX`); the builder clamps values set directly.
    pub max_leaf_prims: usize,
}

impl Default for BottomUpParams {
    /// Greedy by merged area up to 2,000 primitives, PLOC with radius 16 above, leaves of up to 8.
    fn default() -> Self {
        BottomUpParams {
            method: BottomUpMethod::Auto,
            cost: MergeCost::Area,
            radius: 16,
            greedy_max: 2000,
            max_leaf_prims: 8,
        }
    }
}

impl BottomUpParams {
    /// PLOC with a small radius and larger leaves, whatever the input size: the quickest build.
    pub fn fast_build() -> Self {
        BottomUpParams { method: BottomUpMethod::Ploc, radius: 8, max_leaf_prims: 16, ..Self::default() }
    }
    /// A wider PLOC search and the greedy method up to 4,000 primitives.
    pub fn quality() -> Self {
        BottomUpParams { radius: 32, greedy_max: 4000, ..Self::default() }
    }
    /// The method used for `n` primitives.
    pub fn method_for(&self, n: usize) -> BottomUpMethod {
        match self.method {
            BottomUpMethod::Auto if n <= self.greedy_max => BottomUpMethod::Greedy,
            BottomUpMethod::Auto => BottomUpMethod::Ploc,
            m => m,
        }
    }
}

impl BottomUpParams {
    /// The parameters by key, with their ranges.
    pub const PARAMS: &'static [ParamSpec] = &[
        ParamSpec {
            key: "method",
            about: "agglomerative method (auto: greedy up to greedy-max primitives, PLOC above)",
            range: ParamRange::Choice(&["auto", "greedy", "ploc"]),
        },
        ParamSpec {
            key: "cost",
            about: "greedy merge cost",
            range: ParamRange::Choice(&["distance", "volume", "area"]),
        },
        ParamSpec {
            key: "radius",
            about: "PLOC search radius along the Morton order",
            range: ParamRange::Int { min: 1, max: Some(256) },
        },
        ParamSpec {
            key: "greedy-max",
            about: "most primitives for which auto uses the greedy method",
            range: ParamRange::Int { min: 0, max: None },
        },
        ParamSpec {
            key: "leaf",
            about: "most primitives a collapsed leaf may hold (1 = no collapsing)",
            range: ParamRange::Int { min: 1, max: Some(LEAF_HARD_MAX as i64) },
        },
    ];
}

impl ParamSet for BottomUpParams {
    fn specs(&self) -> &'static [ParamSpec] {
        Self::PARAMS
    }
    fn get(&self, key: &str) -> Option<ParamValue> {
        Some(match key {
            "method" => ParamValue::Word(match self.method {
                BottomUpMethod::Auto => "auto",
                BottomUpMethod::Greedy => "greedy",
                BottomUpMethod::Ploc => "ploc",
            }),
            "cost" => ParamValue::Word(match self.cost {
                MergeCost::Distance => "distance",
                MergeCost::Volume => "volume",
                MergeCost::Area => "area",
            }),
            "radius" => ParamValue::count(self.radius),
            "greedy-max" => ParamValue::count(self.greedy_max),
            "leaf" => ParamValue::count(self.max_leaf_prims),
            _ => return None,
        })
    }
    fn put(&mut self, key: &str, v: ParamValue) {
        match (key, v) {
            ("method", ParamValue::Word("greedy")) => self.method = BottomUpMethod::Greedy,
            ("method", ParamValue::Word("ploc")) => self.method = BottomUpMethod::Ploc,
            ("method", _) => self.method = BottomUpMethod::Auto,
            ("cost", ParamValue::Word("distance")) => self.cost = MergeCost::Distance,
            ("cost", ParamValue::Word("volume")) => self.cost = MergeCost::Volume,
            ("cost", _) => self.cost = MergeCost::Area,
            ("radius", v) => self.radius = v.as_usize(),
            ("greedy-max", v) => self.greedy_max = v.as_usize(),
            ("leaf", v) => self.max_leaf_prims = v.as_usize(),
            _ => {}
        }
    }
}

/// Marks a leaf in [`Cluster::kids`].
const NO_CHILD: u32 = u32::MAX;

/// One node of the binary tree the clustering builds. The arena holds the `n` leaves first (leaf `i`
/// is live primitive `i`), then inner nodes in the order they were made, so children always precede
/// their parent and the root is last.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Cluster {
    bounds: Aabb,
    /// Arena indices of the two children, or `[NO_CHILD, NO_CHILD]` for a leaf.
    kids: [u32; 2],
}

impl Cluster {
    fn leaf(bounds: Aabb) -> Self {
        Cluster { bounds, kids: [NO_CHILD; 2] }
    }
    fn is_leaf(&self) -> bool {
        self.kids[0] == NO_CHILD
    }
}

/// Appends the node merging arena nodes `a` and `b`; returns its index.
fn merge(arena: &mut Vec<Cluster>, a: u32, b: u32) -> u32 {
    let bounds = arena[a as usize].bounds.union(arena[b as usize].bounds);
    arena.push(Cluster { bounds, kids: [a, b] });
    (arena.len() - 1) as u32
}

/// Cost of the box merging `a` and `b` under `cost` (double precision: no overflow near the float range).
#[inline]
fn merge_cost(cost: MergeCost, a: &Aabb, b: &Aabb) -> f64 {
    match cost {
        MergeCost::Area => a.union(*b).area_f64(),
        MergeCost::Volume => {
            let u = a.union(*b);
            let e = u.max.as_dvec3() - u.min.as_dvec3();
            e.x * e.y * e.z
        }
        MergeCost::Distance => {
            let d = (a.min.as_dvec3() + a.max.as_dvec3()) - (b.min.as_dvec3() + b.max.as_dvec3());
            d.length_squared()
        }
    }
}

/// Builds the flat node array, the reordered primitive indices and the number of primitives in the tree.
pub(super) fn build<P: Primitives + ?Sized>(prims: &P, params: &BottomUpParams) -> (Vec<Node>, Vec<u32>, usize) {
    let (live, dead) = split_live(prims);
    if live.is_empty() {
        return finish(None, &live, &dead);
    }
    let arena = match params.method_for(live.len()) {
        BottomUpMethod::Greedy => greedy::cluster(&live, params.cost),
        _ => ploc::cluster(&live, params.radius.clamp(1, 256)),
    };
    let (root, ordered) = emit::emit(&arena, &live, params.max_leaf_prims.clamp(1, LEAF_HARD_MAX));
    finish(Some(&root), &ordered, &dead)
}
