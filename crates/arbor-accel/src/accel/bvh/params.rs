//! The build knobs of the top-down BVH builders ([`BvhParams`] for the binned SAH, [`MedianParams`] for
//! the median split), their defaults, presets and valid ranges.

use super::{LEAF_HARD_MAX, MAX_BINS};
use crate::accel::params::{ParamRange, ParamSet, ParamSpec, ParamValue};

/// Build knobs of the SAH BVH; the median build uses only [`BvhParams::max_leaf_prims`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BvhParams {
    /// A node with more primitives is always split; one with at most this many becomes a leaf when
    /// splitting does not lower the SAH cost (median build: always). Valid: `1..=64` (`LEAF_HARD_MAX`);
    /// the builder clamps values set directly.
    pub max_leaf_prims: usize,
    /// Number of SAH bins along the split axis. Valid: `2..=32` (`MAX_BINS`).
    pub bins: usize,
    /// Cost of visiting one node, relative to `intersection_cost`. Valid: finite, `>= 0`.
    pub traversal_cost: f32,
    /// Cost of intersecting one primitive, or one block of `leaf_block` triangles. Valid: finite, `>= 0`.
    pub intersection_cost: f32,
    /// Triangles a leaf tests at once (the SIMD lanes of `wide::LeafBlock`): the SAH counts a leaf's
    /// primitives in blocks of this many, so that it prefers full blocks. Triangle meshes only; other
    /// primitives are tested one at a time and always count as blocks of one. Valid: `1..=8`.
    pub leaf_block: usize,
}

impl Default for BvhParams {
    /// 16 bins, leaves of up to 8 triangles in blocks of 4, and a node visit costing as much as a block
    /// test (Embree's ratio; measured best of 0.5-3 on the peer meshes, `docs/performance.md`).
    fn default() -> Self {
        BvhParams { max_leaf_prims: 8, bins: 16, traversal_cost: 1.0, intersection_cost: 1.0, leaf_block: 4 }
    }
}

impl BvhParams {
    /// Fewer bins and larger leaves: a quicker build for scenes rendered with few rays.
    pub fn fast_build() -> Self {
        BvhParams { max_leaf_prims: 16, bins: 12, ..Self::default() }
    }
    /// More bins and smaller leaves: a slower build for scenes rendered with many rays.
    pub fn quality() -> Self {
        BvhParams { max_leaf_prims: 4, bins: 32, ..Self::default() }
    }
    /// The parameters with every field in its valid range (NaN or negative costs become the defaults).
    pub(super) fn sanitized(&self) -> Self {
        let d = Self::default();
        let cost = |c: f32, dflt: f32| if c.is_finite() && c >= 0.0 { c } else { dflt };
        BvhParams {
            max_leaf_prims: self.max_leaf_prims.clamp(1, LEAF_HARD_MAX),
            bins: self.bins.clamp(2, MAX_BINS),
            traversal_cost: cost(self.traversal_cost, d.traversal_cost),
            intersection_cost: cost(self.intersection_cost, d.intersection_cost),
            leaf_block: self.leaf_block.clamp(1, 8),
        }
    }
}

/// A leaf's primitive count, as every BVH builder accepts it.
const LEAF_RANGE: ParamRange = ParamRange::Int { min: 1, max: Some(LEAF_HARD_MAX as i64) };
/// A cost of the SAH: any finite, non-negative number.
const COST_RANGE: ParamRange = ParamRange::Float { min: 0.0, max: None };

impl BvhParams {
    /// The parameters by key, with their ranges.
    pub const PARAMS: &'static [ParamSpec] = &[
        ParamSpec { key: "leaf", about: "most primitives in a leaf that the SAH may keep", range: LEAF_RANGE },
        ParamSpec {
            key: "bins",
            about: "SAH bins along the split axis",
            range: ParamRange::Int { min: 2, max: Some(MAX_BINS as i64) },
        },
        ParamSpec {
            key: "traversal-cost",
            about: "cost of a node visit relative to a primitive test",
            range: COST_RANGE,
        },
        ParamSpec {
            key: "intersection-cost",
            about: "cost of a primitive test (of a block of triangles)",
            range: COST_RANGE,
        },
        ParamSpec {
            key: "leaf-block",
            about: "triangles tested at once in a leaf, counted as one test by the SAH",
            range: ParamRange::Int { min: 1, max: Some(8) },
        },
    ];
}

impl ParamSet for BvhParams {
    fn specs(&self) -> &'static [ParamSpec] {
        Self::PARAMS
    }
    fn get(&self, key: &str) -> Option<ParamValue> {
        Some(match key {
            "leaf" => ParamValue::count(self.max_leaf_prims),
            "bins" => ParamValue::count(self.bins),
            "traversal-cost" => ParamValue::Float(self.traversal_cost.into()),
            "intersection-cost" => ParamValue::Float(self.intersection_cost.into()),
            "leaf-block" => ParamValue::count(self.leaf_block),
            _ => return None,
        })
    }
    fn put(&mut self, key: &str, v: ParamValue) {
        match key {
            "leaf" => self.max_leaf_prims = v.as_usize(),
            "bins" => self.bins = v.as_usize(),
            "traversal-cost" => self.traversal_cost = v.as_f32(),
            "intersection-cost" => self.intersection_cost = v.as_f32(),
            "leaf-block" => self.leaf_block = v.as_usize(),
            _ => {}
        }
    }
}

/// Parameters of the median build: its only knob is the leaf size (no costs, no bins).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MedianParams {
    /// Most primitives in a leaf. Valid: `1..=64` (`LEAF_HARD_MAX`); the builder clamps values set
    /// directly.
    pub max_leaf_prims: usize,
}

impl Default for MedianParams {
    fn default() -> Self {
        MedianParams { max_leaf_prims: BvhParams::default().max_leaf_prims }
    }
}

impl MedianParams {
    /// The parameters by key, with their ranges.
    pub const PARAMS: &'static [ParamSpec] =
        &[ParamSpec { key: "leaf", about: "most primitives in a leaf", range: LEAF_RANGE }];
}

impl ParamSet for MedianParams {
    fn specs(&self) -> &'static [ParamSpec] {
        Self::PARAMS
    }
    fn get(&self, key: &str) -> Option<ParamValue> {
        (key == "leaf").then_some(ParamValue::count(self.max_leaf_prims))
    }
    fn put(&mut self, key: &str, v: ParamValue) {
        if key == "leaf" {
            self.max_leaf_prims = v.as_usize();
        }
    }
}
