//! Acceleration structures: one contract ([`Accel`]) in the vocabulary of pbrt and Embree, over any set
//! of bounded primitives ([`Primitives`]), and one factory ([`build`]) selected by [`AccelKind`].
//!
//! Every structure returns exactly the hit brute force returns: the smallest `t` in `(0, t_max)`, and
//! among primitives hit at that same `t`, the one with the lowest index. Structures store only primitive
//! indices; the primitives themselves are passed to each query, which keeps builders free of geometry
//! and lets one structure type serve triangles, spheres or whole objects.

mod brute;
pub mod bvh;
mod mesh_prims;

use std::fmt;
use std::str::FromStr;
use std::time::Duration;

use crate::math::{Aabb, Ray, Vec3};

pub use brute::BruteForce;
pub use bvh::{Bvh, BvhParams};

/// A hit on one primitive, before its index is known.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PrimHit {
    /// Ray parameter.
    pub t: f32,
    /// First surface parameter (the barycentric weight of vertex 1 for triangles).
    pub u: f32,
    /// Second surface parameter (the weight of vertex 2 for triangles).
    pub v: f32,
}

/// The closest hit found by a structure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Ray parameter.
    pub t: f32,
    /// Index of the primitive hit.
    pub prim: u32,
    /// Surface parameters, see [`PrimHit`].
    pub u: f32,
    /// Surface parameters, see [`PrimHit`].
    pub v: f32,
}

impl Hit {
    /// `prim` and `h` as a hit.
    #[inline]
    pub fn new(prim: u32, h: PrimHit) -> Self {
        Hit { t: h.t, prim, u: h.u, v: h.v }
    }
    /// True when this hit should replace `best` (closer, or as close with a lower index).
    #[inline]
    pub fn beats(&self, best: &Option<Hit>) -> bool {
        match best {
            None => true,
            Some(b) => self.t < b.t || (self.t == b.t && self.prim < b.prim),
        }
    }
}

/// What a structure indexes: a set of bounded primitives addressed by index `0..len()`.
pub trait Primitives: Sync {
    /// Number of primitives.
    fn len(&self) -> usize;
    /// True when there are none.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// World-space bounds of primitive `i` (may be empty for a primitive that can never be hit).
    fn bounds(&self, i: usize) -> Aabb;
    /// A representative point for splitting (the bounds' centre by default).
    fn centroid(&self, i: usize) -> Vec3 {
        self.bounds(i).center()
    }
    /// The hit of `ray` with primitive `i` in `(0, t_max)`.
    fn intersect(&self, i: usize, ray: &Ray, t_max: f32) -> Option<PrimHit>;
}

/// Counters that describe a built structure, for `arbor info`, the render summary and benchmarks.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct AccelStats {
    /// The structure's name ([`AccelKind::name`]).
    pub kind: &'static str,
    /// Primitives indexed.
    pub primitives: usize,
    /// All nodes, inner and leaves.
    pub nodes: usize,
    /// Leaf nodes.
    pub leaves: usize,
    /// Depth of the deepest leaf (the root has depth 0).
    pub max_depth: usize,
    /// Mean primitive references per non-empty leaf.
    pub mean_leaf_prims: f64,
    /// Surface-area-heuristic cost of the tree (traversal cost 1, intersection cost 1), 0 where meaningless.
    pub sah_cost: f64,
    /// Bytes of the structure's own arrays (nodes, index lists).
    pub bytes: usize,
    /// Wall time of the build.
    pub build_time: Duration,
}

/// The contract every acceleration structure meets.
pub trait Accel<P: Primitives + ?Sized>: Send + Sync {
    /// Bounds of everything indexed.
    fn bounds(&self) -> Aabb;
    /// The closest hit in `(0, t_max)`: smallest `t`, ties to the lowest primitive index.
    fn intersect(&self, prims: &P, ray: &Ray, t_max: f32) -> Option<Hit>;
    /// Whether anything is hit in `(0, t_max)` (shadow rays); may stop at the first hit found.
    fn occluded(&self, prims: &P, ray: &Ray, t_max: f32) -> bool;
    /// Build statistics.
    fn stats(&self) -> AccelStats;
    /// Checks the structure's invariants (children inside parents, every primitive reachable once).
    fn validate(&self, prims: &P) -> Result<(), String>;
}

/// The structures Arbor can build.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum AccelKind {
    /// Tests every primitive: the reference.
    Brute,
    /// Top-down bounding volume hierarchy with binned surface-area-heuristic splits.
    BvhSah,
}

impl AccelKind {
    /// Every kind, in the order they are reported.
    pub const ALL: &'static [AccelKind] = &[AccelKind::Brute, AccelKind::BvhSah];

    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            AccelKind::Brute => "brute",
            AccelKind::BvhSah => "bvh-sah",
        }
    }
}

impl fmt::Display for AccelKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for AccelKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        AccelKind::ALL.iter().copied().find(|k| k.name() == s).ok_or_else(|| {
            let names: Vec<_> = AccelKind::ALL.iter().map(|k| k.name()).collect();
            format!("unknown acceleration structure '{s}' (expected one of: {})", names.join(", "))
        })
    }
}

/// Builds a structure of `kind` over `prims` (pbrt's `CreateAccelerator`). In debug builds the result
/// is validated before it is returned.
pub fn build<P: Primitives + ?Sized + 'static>(kind: AccelKind, prims: &P) -> Box<dyn Accel<P>> {
    let accel: Box<dyn Accel<P>> = match kind {
        AccelKind::Brute => Box::new(BruteForce::build(prims)),
        AccelKind::BvhSah => Box::new(Bvh::build_sah(prims, &BvhParams::default())),
    };
    #[cfg(debug_assertions)]
    if let Err(e) = accel.validate(prims) {
        panic!("{kind} built an invalid structure: {e}");
    }
    accel
}
