//! Acceleration structures. The public door is [`Structure`]: a structure built by an [`AccelConfig`]
//! (which structure, and its `*Params`) over primitives it holds, a [`crate::geometry::TriangleMesh`] or
//! anything that implements [`Primitives`], answering closest-hit and any-hit queries, and closest-point
//! queries over primitives that can tell their closest point (triangle meshes).
//!
//! Every structure returns exactly the hit brute force returns: the smallest `t` in `(0, t_max)`, and
//! among primitives hit at that same `t`, the one with the lowest index. Inside, structures store only
//! primitive indices and are given the primitives with each query (the hidden `Accel` contract in the
//! vocabulary of pbrt and Embree), which keeps builders free of geometry and lets one structure type
//! serve triangles, spheres or whole objects (the renderer's two-level scene); [`Structure`] pairs a
//! structure with its primitives so that it cannot be asked about others.
//!
//! One folder per structure: `brute.rs`, `octree/`, `kdtree/`, `bvh/` (median, binned SAH and bottom-up
//! builders sharing one node layout and one traversal). Their node layouts are not part of the API.

mod brute;
#[doc(hidden)]
pub mod bvh;
mod closest;
mod config;
#[doc(hidden)]
pub mod kdtree;
mod mesh_prims;
mod nearest;
#[doc(hidden)]
pub mod octree;
mod params;
mod stats;
mod structure;
#[cfg(test)]
mod watertight_tests;

use std::fmt;
use std::str::FromStr;
use std::time::Duration;

use crate::math::{Aabb, DVec3, Ray, Vec3};

#[doc(hidden)]
pub use brute::BruteForce;
#[doc(hidden)]
pub use bvh::Bvh;
pub use bvh::{BottomUpMethod, BottomUpParams, BvhParams, MedianParams, MergeCost};
pub use config::{AccelConfig, KindParam};
#[doc(hidden)]
pub use kdtree::KdTree;
pub use kdtree::KdTreeParams;
pub use nearest::{ClosestPointUnsupported, Nearest, PrimPoint};
#[doc(hidden)]
pub use octree::Octree;
pub use octree::OctreeParams;
#[doc(hidden)]
pub use params::ParamSet;
pub use params::{ConfigError, ParamRange, ParamSpec, ParamValue};
pub use structure::{Structure, ValidateError};

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
///
/// [`crate::geometry::TriangleMesh`] implements it; so can any other shape. Spheres, for example:
///
/// ```
/// use arbor_accel::accel::{AccelConfig, PrimHit, Primitives, Structure};
/// use arbor_accel::geometry::Sphere;
/// use arbor_accel::math::{Aabb, Ray, Transform, Vec3};
///
/// struct Balls(Vec<Sphere>);
///
/// impl Primitives for Balls {
///     fn len(&self) -> usize {
///         self.0.len()
///     }
///     fn bounds(&self, i: usize) -> Aabb {
///         self.0[i].bounds()
///     }
///     fn intersect(&self, i: usize, ray: &Ray, t_max: f32) -> Option<PrimHit> {
///         self.0[i].intersect(ray, t_max).map(|t| PrimHit::new(t, 0.0, 0.0))
///     }
/// }
///
/// let ball = |x: f32| Sphere { center: Vec3::new(x, 0.0, 0.0), radius: 0.5, transform: Transform::IDENTITY };
/// let balls = Balls((0..100).map(|i| ball(i as f32)).collect());
/// let structure = Structure::build(&"kdtree".parse()?, balls)?;
/// let along_x = Ray::new(Vec3::new(-10.0, 0.0, 0.0), Vec3::X);
/// let hit = structure.intersect(&along_x, f32::INFINITY).unwrap();
/// assert_eq!(hit.prim, 0);
/// assert!((hit.t - 9.5).abs() < 1e-5);
/// let from_above = Ray::new(Vec3::new(42.0, 5.0, 0.0), -Vec3::Y);
/// assert_eq!(structure.intersect(&from_above, f32::INFINITY).unwrap().prim, 42);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
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
    #[doc(hidden)]
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
    /// The point of primitive `i` closest to `p`, inside [`Primitives::bounds`] (closest-point queries
    /// prune by box distance and rely on it); `None` when `i` can never be the answer. Only asked when
    /// [`Primitives::has_closest_point`] is true.
    fn closest_point(&self, i: usize, p: DVec3) -> Option<PrimPoint> {
        let _ = (i, p);
        None
    }
    /// Whether [`Primitives::closest_point`] answers (false by default: [`Structure::closest_point`]
    /// then refuses the query instead of answering wrongly).
    fn has_closest_point(&self) -> bool {
        false
    }
    /// The triangle mesh these primitives are, when they are one (primitive `i` is triangle `i`): lets a
    /// structure keep the triangles' corners in its own leaf order and test them without going through
    /// [`Primitives::intersect`], with the same triangle test and so the same hits.
    #[doc(hidden)]
    fn triangle_mesh(&self) -> Option<&crate::geometry::TriangleMesh> {
        None
    }
}

/// The work one query did, for the traversal-cost heatmap and benchmarks.
#[doc(hidden)]
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

/// The contract every acceleration structure meets: the primitives come with each query. Internal (the
/// renderer's two-level scene and the benchmarks); [`Structure`] is the public door.
#[doc(hidden)]
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
    /// The boxes of the nodes (cells) at `depth` below the root (which has depth 0), for the boxes debug
    /// view: the nodes whose depths [`Accel::stats`] counts (a BVH's binary tree, not the 8-wide tree
    /// its queries read), so `stats().max_depth` is the deepest level with a box. An octree leaves out
    /// its empty leaves (regions holding nothing).
    fn boxes_at_depth(&self, prims: &P, depth: usize) -> Vec<Aabb>;
    /// The primitive nearest to `p` within squared distance `max_dist2`, its point nearest to `p` and
    /// their squared distance; ties to the lowest index (see `nearest.rs`). Asked only of primitives
    /// that answer [`Primitives::closest_point`].
    fn closest_point(&self, prims: &P, p: DVec3, max_dist2: f64) -> Option<Nearest>;
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
    /// [`Accel::intersect_many`] for rays in a coherent order (a scanner's rows of parallel beams, a
    /// camera's pixels row by row): the same hits. A structure may trace runs of rays that start close
    /// together and point the same way as packets (the BVH does, `bvh/wide/packet.rs`); where such rays
    /// diverge or many miss, a packet can cost more than its rays alone (Whitted camera rays measured
    /// 0.95-0.99x), so the caller chooses. The default is [`Accel::intersect_many`].
    ///
    /// # Panics
    /// When `rays`, `t_max` and `out` differ in length.
    fn intersect_many_coherent(&self, prims: &P, rays: &[Ray], t_max: &[f32], out: &mut [Option<Hit>]) {
        self.intersect_many(prims, rays, t_max, out)
    }
    /// [`Accel::occluded`] for a batch: `out[i]` becomes whether `rays[i]` hits anything in
    /// `(0, t_max[i])`. A structure may trace several rays at once (the BVH interleaves two); the default
    /// asks one query per ray.
    ///
    /// # Panics
    /// When `rays`, `t_max` and `out` differ in length.
    fn occluded_many(&self, prims: &P, rays: &[Ray], t_max: &[f32], out: &mut [bool]) {
        assert!(
            rays.len() == t_max.len() && rays.len() == out.len(),
            "a batch's rays, t_max and answers differ in length"
        );
        for ((o, r), &t) in out.iter_mut().zip(rays).zip(t_max) {
            *o = self.occluded(prims, r, t);
        }
    }
}

/// The structures Arbor can build.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
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

    /// The build parameters this kind takes (`--accel-param KEY=VALUE`): what they mean and their
    /// ranges. Their defaults are the values of `AccelConfig::from(kind)`.
    ///
    /// ```
    /// use arbor_accel::accel::{AccelConfig, AccelKind};
    ///
    /// let kind = AccelKind::KdTree;
    /// let defaults = AccelConfig::from(kind);
    /// for p in kind.params() {
    ///     println!("{:<18} {:<16} {:<8} {}", p.key, p.range, defaults.get(p.key).unwrap(), p.about);
    /// }
    /// assert_eq!(kind.params().iter().map(|p| p.key).collect::<Vec<_>>(),
    ///            ["traversal-cost", "intersection-cost", "empty-bonus", "depth"]);
    /// assert!(AccelKind::Brute.params().is_empty());
    /// ```
    pub fn params(self) -> &'static [ParamSpec] {
        AccelConfig::from(self).params()
    }
}

impl fmt::Display for AccelKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for AccelKind {
    type Err = ConfigError;
    fn from_str(s: &str) -> Result<Self, ConfigError> {
        let name = s.trim();
        AccelKind::ALL
            .iter()
            .copied()
            .find(|k| k.name() == name)
            .ok_or_else(|| ConfigError::UnknownKind { name: name.to_string() })
    }
}

/// Builds a structure of `kind` with its default parameters over `prims` (pbrt's `CreateAccelerator`),
/// behind the internal contract. In debug builds the result is validated before it is returned.
#[doc(hidden)]
pub fn build<P: Primitives + ?Sized + 'static>(kind: AccelKind, prims: &P) -> Box<dyn Accel<P>> {
    match AccelConfig::from(kind).build_accel(prims) {
        Ok(accel) => accel,
        Err(e) => unreachable!("default parameters are always valid: {e}"),
    }
}
