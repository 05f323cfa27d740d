//! The public door: [`Structure`] holds the primitives it was built over (owned, or shared through an
//! [`Arc`] as the renderer shares a mesh between its instances) together with the built structure, so
//! a query can only ever be answered against those primitives. Queries: closest hit and any hit of rays
//! (one or a batch), and the closest point on the primitives to a point (`nearest.rs`).

use std::fmt;
use std::sync::Arc;

use super::{
    Accel, AccelConfig, AccelKind, AccelStats, ClosestPointUnsupported, ConfigError, Hit, Nearest, Primitives,
};
use crate::geometry::TriangleMesh;
use crate::math::{Aabb, DVec3, Ray};

/// An acceleration structure over primitives it holds: by default a [`TriangleMesh`], or anything
/// that implements [`Primitives`].
///
/// Every query returns exactly what testing every primitive would: the closest hit is the smallest
/// `t` in `(0, t_max)`, and among primitives hit at that same `t`, the one with the lowest index.
///
/// ```
/// use arbor_accel::accel::{AccelConfig, Structure};
/// use arbor_accel::geometry::TriangleMesh;
/// use arbor_accel::math::{Ray, Vec3};
///
/// // A unit square in the plane z = 0, as two triangles.
/// let mesh = TriangleMesh::from_arrays(
///     vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
///     vec![[0, 1, 2], [0, 2, 3]],
/// )?;
/// let kdtree = Structure::build(&"kdtree".parse()?, mesh)?;
/// let down = Ray::new(Vec3::new(0.25, 0.75, 1.0), Vec3::new(0.0, 0.0, -1.0));
/// let hit = kdtree.intersect(&down, f32::INFINITY).expect("the ray hits the square");
/// assert_eq!((hit.t, hit.prim), (1.0, 1));
/// assert!(kdtree.occluded(&down, 2.0));
/// assert!(!kdtree.occluded(&down, 0.5), "the square lies beyond t_max");
/// assert_eq!(kdtree.stats().primitives, 2);
/// kdtree.validate()?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct Structure<P: Primitives + ?Sized + Send + 'static = TriangleMesh> {
    prims: Arc<P>,
    accel: Box<dyn Accel<P>>,
    kind: AccelKind,
}

impl<P: Primitives + Send + 'static> Structure<P> {
    /// Builds the structure `config` describes over `prims`, which it keeps. An error names a
    /// parameter outside its range (see [`AccelConfig::check`]).
    pub fn build(config: &AccelConfig, prims: P) -> Result<Self, ConfigError> {
        Self::build_shared(config, Arc::new(prims))
    }
}

impl<P: Primitives + ?Sized + Send + 'static> Structure<P> {
    /// [`Structure::build`] over primitives shared with others (one mesh under several structures, or
    /// with the caller).
    pub fn build_shared(config: &AccelConfig, prims: Arc<P>) -> Result<Self, ConfigError> {
        let accel = config.build_accel(prims.as_ref())?;
        Ok(Structure { prims, accel, kind: config.kind() })
    }

    /// The primitives the structure was built over.
    pub fn primitives(&self) -> &Arc<P> {
        &self.prims
    }

    /// Which structure this is.
    pub fn kind(&self) -> AccelKind {
        self.kind
    }

    /// Bounds of every primitive that can be hit (empty when none can).
    pub fn bounds(&self) -> Aabb {
        self.accel.bounds()
    }

    /// The closest hit of `ray` in `(0, t_max)`: smallest `t`, ties to the lowest primitive index.
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        self.accel.intersect(&self.prims, ray, t_max)
    }

    /// [`Structure::intersect`] for a batch: `out[i]` becomes the closest hit of `rays[i]` in
    /// `(0, t_max[i])`, the same hit as a query of its own (a structure may trace several rays at once).
    ///
    /// # Panics
    /// When `rays`, `t_max` and `out` differ in length.
    pub fn intersect_many(&self, rays: &[Ray], t_max: &[f32], out: &mut [Option<Hit>]) {
        self.accel.intersect_many(&self.prims, rays, t_max, out);
    }

    /// [`Structure::intersect_many`] for rays in a coherent order ([`Accel::intersect_many_coherent`]).
    pub fn intersect_many_coherent(&self, rays: &[Ray], t_max: &[f32], out: &mut [Option<Hit>]) {
        self.accel.intersect_many_coherent(&self.prims, rays, t_max, out);
    }

    /// Whether anything is hit in `(0, t_max)` (shadow rays); stops at the first hit found.
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.accel.occluded(&self.prims, ray, t_max)
    }

    /// [`Structure::occluded`] for a batch: `out[i]` becomes whether `rays[i]` hits anything in
    /// `(0, t_max[i])`, the same answer as a query of its own (the BVH traces two rays at once).
    ///
    /// ```
    /// use arbor_accel::accel::{AccelConfig, Structure};
    /// use arbor_accel::geometry::TriangleMesh;
    /// use arbor_accel::math::{Ray, Vec3};
    ///
    /// let mesh = TriangleMesh::from_arrays(vec![[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2]])?;
    /// let bvh = Structure::build(&AccelConfig::default(), mesh)?;
    /// let rays: Vec<Ray> = [0.0, 5.0]
    ///     .iter()
    ///     .map(|&x| Ray::new(Vec3::new(x, 0.0, -1.0), Vec3::Z))
    ///     .collect();
    /// let mut blocked = vec![false; rays.len()];
    /// bvh.occluded_many(&rays, &[10.0, 10.0], &mut blocked);
    /// assert_eq!(blocked, [true, false]);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    ///
    /// # Panics
    /// When `rays`, `t_max` and `out` differ in length.
    pub fn occluded_many(&self, rays: &[Ray], t_max: &[f32], out: &mut [bool]) {
        self.accel.occluded_many(&self.prims, rays, t_max, out);
    }

    /// The primitive nearest to `p`, its point nearest to `p` (in `f64`) and their squared distance,
    /// among the primitives within `max_distance` (squared distance at most `max_distance²`; `inf` for
    /// no bound): the smallest squared distance, ties to the lowest primitive index, exactly what
    /// brute force returns whatever the structure. `None` when nothing is within the bound, for a
    /// non-finite `p`, and for a NaN or negative `max_distance`. Triangles with a non-finite corner are
    /// never the answer. An error, never a wrong answer, when the primitives cannot tell their closest
    /// point ([`Primitives::has_closest_point`]; triangle meshes can).
    ///
    /// ```
    /// use arbor_accel::accel::{AccelConfig, Structure};
    /// use arbor_accel::geometry::TriangleMesh;
    /// use arbor_accel::math::DVec3;
    ///
    /// // A unit square in the plane z = 0, as two triangles sharing the diagonal (0,0)-(1,1).
    /// let mesh = TriangleMesh::from_arrays(
    ///     vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
    ///     vec![[0, 1, 2], [0, 2, 3]],
    /// )?;
    /// let octree = Structure::build(&"octree".parse()?, mesh)?;
    /// let above = octree.closest_point(DVec3::new(0.25, 0.75, 2.0), f64::INFINITY)?.unwrap();
    /// assert_eq!((above.prim, above.point, above.dist2), (1, DVec3::new(0.25, 0.75, 0.0), 4.0));
    /// // Beyond the corner (1, 1), which both triangles share: a tie, to the lower index.
    /// let corner = octree.closest_point(DVec3::new(2.0, 2.0, 0.0), f64::INFINITY)?.unwrap();
    /// assert_eq!((corner.prim, corner.point, corner.distance()), (0, DVec3::ONE.with_z(0.0), 2f64.sqrt()));
    /// assert_eq!(octree.closest_point(DVec3::new(0.5, 0.5, 3.0), 2.0)?, None, "nothing within 2");
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn closest_point(&self, p: DVec3, max_distance: f64) -> Result<Option<Nearest>, ClosestPointUnsupported> {
        self.check_closest_point()?;
        Ok(self.accel.closest_point(&self.prims, p, max_dist2(max_distance)))
    }

    /// [`Structure::closest_point`] for a batch: `out[i]` becomes the answer for `points[i]`.
    ///
    /// # Panics
    /// When `points` and `out` differ in length.
    pub fn closest_points_many(
        &self,
        points: &[DVec3],
        max_distance: f64,
        out: &mut [Option<Nearest>],
    ) -> Result<(), ClosestPointUnsupported> {
        assert_eq!(points.len(), out.len(), "a batch's points and answers differ in length");
        self.check_closest_point()?;
        let d2 = max_dist2(max_distance);
        for (o, &p) in out.iter_mut().zip(points) {
            *o = self.accel.closest_point(&self.prims, p, d2);
        }
        Ok(())
    }

    /// Whether closest-point queries are answered (`Ok`) or refused with the error every one of them
    /// would return, asked once before a batch split across threads.
    pub fn check_closest_point(&self) -> Result<(), ClosestPointUnsupported> {
        if self.prims.has_closest_point() {
            Ok(())
        } else {
            Err(ClosestPointUnsupported { kind: self.kind })
        }
    }

    /// Statistics of the built structure (nodes, leaves, depth, SAH cost, bytes, build time).
    pub fn stats(&self) -> AccelStats {
        self.accel.stats()
    }

    /// Checks the structure's invariants against its primitives (children inside parents, every
    /// primitive reachable); an error says which one fails where. Debug builds check once when built.
    pub fn validate(&self) -> Result<(), ValidateError> {
        self.accel.validate(&self.prims).map_err(|message| ValidateError { kind: self.kind, message })
    }
}

impl<P: Primitives + ?Sized + Send + 'static> fmt::Debug for Structure<P> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = self.stats();
        f.debug_struct("Structure")
            .field("kind", &self.kind)
            .field("primitives", &s.primitives)
            .field("nodes", &s.nodes)
            .finish_non_exhaustive()
    }
}

/// The squared bound of a closest-point query: NaN (nothing within it) for a NaN or negative distance.
fn max_dist2(max_distance: f64) -> f64 {
    if max_distance >= 0.0 {
        max_distance * max_distance
    } else {
        f64::NAN
    }
}

/// A broken invariant found by [`Structure::validate`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ValidateError {
    /// The structure checked.
    pub kind: AccelKind,
    /// Which invariant fails, and where.
    pub message: String,
}

impl fmt::Display for ValidateError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.kind, self.message)
    }
}

impl std::error::Error for ValidateError {}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::build;
    use crate::math::Vec3;
    use crate::test_rng::Rng;

    fn soup(n: usize, seed: u64) -> TriangleMesh {
        let mut rng = Rng(seed);
        let mut positions = Vec::new();
        for _ in 0..n {
            let c = [rng.f32() * 10.0, rng.f32() * 10.0, rng.f32() * 10.0];
            for _ in 0..3 {
                positions.push([c[0] + rng.f32() - 0.5, c[1] + rng.f32() - 0.5, c[2] + rng.f32() - 0.5]);
            }
        }
        let triangles = (0..n as u32).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
        TriangleMesh::from_arrays(positions, triangles).unwrap()
    }

    fn rays(n: usize, seed: u64) -> Vec<Ray> {
        let mut rng = Rng(seed);
        (0..n)
            .map(|_| {
                let o = Vec3::new(rng.f32() * 14.0 - 2.0, rng.f32() * 14.0 - 2.0, -3.0);
                let d = Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, 1.0).normalize();
                Ray::new(o, d)
            })
            .collect()
    }

    /// The front door answers what the internal contract (given the same mesh) answers, for every
    /// structure, one ray at a time and in batches.
    #[test]
    fn structure_answers_the_same_hits_as_the_internal_contract() {
        let mesh = soup(400, 3);
        let rays = rays(500, 4);
        let t_max: Vec<f32> = (0..rays.len()).map(|i| if i % 5 == 0 { 4.0 } else { f32::INFINITY }).collect();
        let shared = Arc::new(mesh.clone());
        for &kind in AccelKind::ALL {
            let old = build(kind, &mesh);
            let door = Structure::build_shared(&AccelConfig::from(kind), Arc::clone(&shared)).unwrap();
            assert_eq!(door.kind(), kind);
            assert_eq!(door.bounds(), old.bounds());
            assert_eq!(door.stats().nodes, old.stats().nodes);
            door.validate().unwrap();
            let mut many = vec![None; rays.len()];
            door.intersect_many(&rays, &t_max, &mut many);
            let mut blocked = vec![false; rays.len()];
            door.occluded_many(&rays, &t_max, &mut blocked);
            let mut hits = 0;
            for (i, r) in rays.iter().enumerate() {
                let want = old.intersect(&mesh, r, t_max[i]);
                assert_eq!(door.intersect(r, t_max[i]), want, "{kind} ray {i}");
                assert_eq!(many[i], want, "{kind} ray {i} in a batch");
                assert_eq!(door.occluded(r, t_max[i]), old.occluded(&mesh, r, t_max[i]), "{kind} ray {i}");
                assert_eq!(blocked[i], want.is_some(), "{kind} ray {i} occluded in a batch");
                hits += want.is_some() as usize;
            }
            assert!(hits > 50 && hits < rays.len(), "{kind}: {hits} hits is not a useful test");
        }
        assert!(Arc::strong_count(&shared) == 1, "structures dropped with their share of the mesh");
    }

    /// The boxes view's levels are the ones the statistics count: for every structure, each depth from
    /// the root's (0) to `max_depth` has boxes, none below, and they are all the nodes the statistics
    /// count (but an octree's empty leaves, which hold nothing).
    #[test]
    fn structure_boxes_at_each_depth_are_the_nodes_the_statistics_count() {
        let mesh = soup(3000, 11);
        for &kind in AccelKind::ALL {
            let accel = build(kind, &mesh);
            let s = accel.stats();
            let levels: Vec<usize> = (0..=s.max_depth + 1).map(|d| accel.boxes_at_depth(&mesh, d).len()).collect();
            assert!(levels[..=s.max_depth].iter().all(|&n| n > 0), "{kind}: boxes per level {levels:?}");
            assert_eq!(levels[s.max_depth + 1], 0, "{kind}: boxes below depth max {}: {levels:?}", s.max_depth);
            let total: usize = levels.iter().sum();
            if kind == AccelKind::Octree {
                assert!(total <= s.nodes && total > s.nodes - s.leaves, "{kind}: {total} boxes, {s:?}");
            } else {
                assert_eq!(total, s.nodes, "{kind}: {levels:?}");
            }
            assert!(s.max_depth > 0 || kind == AccelKind::Brute, "{kind}: a tree that does not test depths");
        }
    }

    #[test]
    fn structure_build_refuses_parameters_outside_their_range() {
        let config = AccelConfig::Octree(crate::accel::OctreeParams { max_depth: 40, ..Default::default() });
        let err = Structure::build(&config, soup(3, 1)).unwrap_err();
        assert_eq!(err.to_string(), "parameter 'depth': 40 is outside its range 0..=16");
    }

    #[test]
    fn structure_over_an_empty_mesh_hits_nothing() {
        let s = Structure::build(&AccelConfig::default(), TriangleMesh::default()).unwrap();
        let r = Ray::new(Vec3::ZERO, Vec3::X);
        assert_eq!(s.intersect(&r, f32::INFINITY), None);
        assert!(!s.occluded(&r, f32::INFINITY));
        assert!(s.bounds().is_empty());
        assert!(format!("{s:?}").starts_with("Structure { kind: BvhSah, primitives: 0"));
    }
}
