//! Acceleration structures: one contract ([`Accel`]) in the vocabulary of pbrt and Embree, over any set
//! of bounded primitives ([`Primitives`]), and one factory ([`build`], [`build_with`]) selected by
//! [`AccelKind`] and tuned by each structure's `*Params` ([`AccelSpec`]).
//!
//! Every structure returns exactly the hit brute force returns: the smallest `t` in `(0, t_max)`, and
//! among primitives hit at that same `t`, the one with the lowest index. Structures store only primitive
//! indices; the primitives themselves are passed to each query, which keeps builders free of geometry
//! and lets one structure type serve triangles, spheres or whole objects (the two-level scene).
//!
//! One folder per structure: `brute.rs`, `octree/`, `kdtree/`, `bvh/` (median, binned SAH and bottom-up
//! builders sharing one node layout and one traversal).

mod brute;
pub mod bvh;
mod closest;
pub mod kdtree;
mod mesh_prims;
pub mod octree;
mod params;

use std::fmt;
use std::str::FromStr;
use std::time::Duration;

use crate::math::{Aabb, Ray, Vec3};

pub use brute::BruteForce;
pub use bvh::{BottomUpParams, Bvh, BvhParams, MedianParams};
pub use kdtree::{KdTree, KdTreeParams};
pub use octree::{Octree, OctreeParams};
pub use params::{AccelSpec, Params};

/// How much every structure widens its box and interval tests, relative to the extent in `t` of the box
/// (or root) along the ray's major axis: 2^-16, about 128 ulps.
///
/// Why: the watertight triangle test computes `t` as a barycentric blend of the corners' distances
/// along the major axis, so the error of a reported `t` scales with the triangle's extent along the ray,
/// not with `t`, and can put a hit slightly outside the box or cell that holds the triangle. Pruning on
/// an exact interval could then lose the closest hit, or a tie's winner, relative to brute force.
/// `bvh/traverse.rs` argues the bound in full; the conformance suite fails with 16 times less.
pub(crate) const BOX_SLACK: f32 = 1.0 / 65_536.0;

/// A hit on one primitive, before its index is known.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PrimHit {
    /// Ray parameter.
    pub t: f32,
    /// First surface parameter (the barycentric weight of vertex 1 for triangles).
    pub u: f32,
    /// Second surface parameter (the weight of vertex 2 for triangles).
    pub v: f32,
    /// For a primitive that holds primitives of its own (an object of the two-level scene), which one
    /// was hit; 0 otherwise.
    pub sub: u32,
}

impl PrimHit {
    /// A hit on a simple primitive.
    #[inline]
    pub fn new(t: f32, u: f32, v: f32) -> Self {
        PrimHit { t, u, v, sub: 0 }
    }
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
    /// The primitive hit inside primitive `prim`, see [`PrimHit::sub`].
    pub sub: u32,
}

impl Hit {
    /// `prim` and `h` as a hit.
    #[inline]
    pub fn new(prim: u32, h: PrimHit) -> Self {
        Hit { t: h.t, prim, u: h.u, v: h.v, sub: h.sub }
    }
    /// True when this hit should replace `best` (closer, or as close with a lower index). Hits inside
    /// one primitive at equal `t` were already resolved by that primitive's own structure.
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
    /// Whether primitive `i` is hit anywhere in `(0, t_max)` (shadow rays). The default asks for the
    /// closest hit; primitives that are structures stop at the first.
    fn occludes(&self, i: usize, ray: &Ray, t_max: f32) -> bool {
        self.intersect(i, ray, t_max).is_some()
    }
    /// [`Primitives::intersect`], adding the work done to `counts` (one primitive test by default; a
    /// primitive that is itself a structure, as objects of the two-level scene are, adds its traversal).
    fn intersect_counted(&self, i: usize, ray: &Ray, t_max: f32, counts: &mut TraversalCounts) -> Option<PrimHit> {
        counts.prims += 1;
        self.intersect(i, ray, t_max)
    }
    /// Whether primitive `i` has a point in `b` (for structures that put a primitive in every cell it
    /// touches). The default, bounds overlap, is conservative; triangles answer exactly.
    fn overlaps_box(&self, i: usize, b: &Aabb) -> bool {
        self.bounds(i).overlaps(b)
    }
    /// The bounds of the part of primitive `i` inside `b` ("perfect splits" of kd-trees). The default,
    /// bounds cut by `b`, is conservative; triangles are clipped exactly.
    fn clipped_bounds(&self, i: usize, b: &Aabb) -> Aabb {
        self.bounds(i).intersection(*b)
    }
    /// The triangle mesh these primitives are, when they are one (primitive `i` is triangle `i`): lets a
    /// structure keep the triangles' corners in its own leaf order and test them without going through
    /// [`Primitives::intersect`], with the same triangle test and so the same hits.
    fn triangle_mesh(&self) -> Option<&crate::geometry::TriangleMesh> {
        None
    }
}

/// The work one query did, for the traversal-cost heatmap and benchmarks.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TraversalCounts {
    /// Nodes (cells) visited.
    pub nodes: u32,
    /// Primitives tested.
    pub prims: u32,
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
    /// Mean depth of the leaves.
    pub mean_depth: f64,
    /// Primitive references in leaves per primitive: 1 for hierarchies, more where cells share
    /// primitives (octree, kd-tree).
    pub refs_per_prim: f64,
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
    /// Checks the structure's invariants (children inside parents, every primitive reachable).
    fn validate(&self, prims: &P) -> Result<(), String>;
    /// [`Accel::intersect`], adding the nodes visited and primitives tested to `counts`.
    fn intersect_counted(&self, prims: &P, ray: &Ray, t_max: f32, counts: &mut TraversalCounts) -> Option<Hit>;
    /// The boxes of the nodes (cells) at `depth` below the root, for the boxes debug view.
    fn boxes_at_depth(&self, depth: usize) -> Vec<Aabb>;
    /// [`Accel::intersect`] for a batch: `out[i]` becomes the closest hit of `rays[i]` in
    /// `(0, t_max[i])`, the same hit as a query of its own. A structure may trace several rays at once
    /// (the BVH interleaves two); the default asks one query per ray.
    ///
    /// # Panics
    /// When `rays`, `t_max` and `out` differ in length.
    fn intersect_many(&self, prims: &P, rays: &[Ray], t_max: &[f32], out: &mut [Option<Hit>]) {
        assert!(
            rays.len() == t_max.len() && rays.len() == out.len(),
            "a batch's rays, t_max and hits differ in length"
        );
        for ((o, r), &t) in out.iter_mut().zip(rays).zip(t_max) {
            *o = self.intersect(prims, r, t);
        }
    }
}

/// The structures Arbor can build.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum AccelKind {
    /// Tests every primitive: the reference.
    Brute,
    /// Regular octree over the scene's bounding cube; primitives go into every cell they overlap.
    Octree,
    /// Kd-tree with surface-area-heuristic splits (Wald and Havran 2006).
    KdTree,
    /// Bounding volume hierarchy split at the median centroid of the longest axis.
    BvhMedian,
    /// Bounding volume hierarchy with binned surface-area-heuristic splits (the default).
    BvhSah,
    /// Bounding volume hierarchy built bottom-up by agglomerative clustering (greedy or PLOC).
    BvhBottomUp,
}

impl AccelKind {
    /// Every kind, in the order they are reported.
    pub const ALL: &'static [AccelKind] = &[
        AccelKind::Brute,
        AccelKind::Octree,
        AccelKind::KdTree,
        AccelKind::BvhMedian,
        AccelKind::BvhSah,
        AccelKind::BvhBottomUp,
    ];

    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            AccelKind::Brute => "brute",
            AccelKind::Octree => "octree",
            AccelKind::KdTree => "kdtree",
            AccelKind::BvhMedian => "bvh-median",
            AccelKind::BvhSah => "bvh-sah",
            AccelKind::BvhBottomUp => "bvh-bottom-up",
        }
    }

    /// The build parameters this kind takes (`--accel-param KEY=VALUE`), with what they mean.
    pub fn param_keys(self) -> &'static [(&'static str, &'static str)] {
        match self {
            AccelKind::Brute => &[],
            AccelKind::Octree => OctreeParams::KEYS,
            AccelKind::KdTree => KdTreeParams::KEYS,
            AccelKind::BvhMedian => MedianParams::KEYS,
            AccelKind::BvhSah => BvhParams::KEYS,
            AccelKind::BvhBottomUp => BottomUpParams::KEYS,
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

impl AccelSpec {
    /// Checks that every parameter applies to the kind and parses, without building anything.
    pub fn check(&self) -> Result<(), String> {
        match self.kind {
            AccelKind::Brute => self.parse::<params::NoParams>().map(drop),
            AccelKind::Octree => self.parse::<OctreeParams>().map(drop),
            AccelKind::KdTree => self.parse::<KdTreeParams>().map(drop),
            AccelKind::BvhMedian => self.parse::<MedianParams>().map(drop),
            AccelKind::BvhSah => self.parse::<BvhParams>().map(drop),
            AccelKind::BvhBottomUp => self.parse::<BottomUpParams>().map(drop),
        }
    }
}

/// Builds a structure of `kind` with its default parameters over `prims` (pbrt's `CreateAccelerator`).
/// In debug builds the result is validated before it is returned.
pub fn build<P: Primitives + ?Sized + 'static>(kind: AccelKind, prims: &P) -> Box<dyn Accel<P>> {
    match build_with(&AccelSpec::new(kind), prims) {
        Ok(accel) => accel,
        Err(e) => unreachable!("default parameters are always valid: {e}"),
    }
}

/// Builds the structure `spec` describes over `prims`; an error names a parameter that does not apply
/// or does not parse. In debug builds the result is validated before it is returned.
pub fn build_with<P: Primitives + ?Sized + 'static>(spec: &AccelSpec, prims: &P) -> Result<Box<dyn Accel<P>>, String> {
    let accel: Box<dyn Accel<P>> = match spec.kind {
        AccelKind::Brute => {
            spec.parse::<params::NoParams>()?;
            Box::new(BruteForce::build(prims))
        }
        AccelKind::Octree => Box::new(Octree::build(prims, &spec.parse()?)),
        AccelKind::KdTree => Box::new(KdTree::build(prims, &spec.parse()?)),
        AccelKind::BvhMedian => Box::new(Bvh::build_median(prims, &spec.parse()?)),
        AccelKind::BvhSah => Box::new(Bvh::build_sah(prims, &spec.parse()?)),
        AccelKind::BvhBottomUp => Box::new(Bvh::build_bottom_up(prims, &spec.parse()?)),
    };
    #[cfg(debug_assertions)]
    if let Err(e) = accel.validate(prims) {
        panic!("{} built an invalid structure: {e}", spec.kind);
    }
    Ok(accel)
}
