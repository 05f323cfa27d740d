//! The runtime geometry, in two levels (Embree's scenes and instances): every mesh has its own
//! acceleration structure over its triangles in object space, and one top-level structure of the same
//! kind indexes the scene's objects (meshes, spheres, instances) by their world bounds. An object with a
//! transform is intersected by taking the ray into its object space (the direction is not normalised,
//! so `t` is the same in both spaces); a `MeshInstance` reuses its base mesh's geometry and structure
//! through its own transform, without copying either. Infinite planes have no bounds and are tested one
//! by one after the hierarchy.
//!
//! Moving objects (motion blur) translate over the shutter interval: the top level bounds each by its
//! swept box (the union of its boxes at times 0 and 1, exact for a translation), and a ray meets the
//! object where it is at the ray's time by moving back by the object's displacement at that time, so
//! the structures below stay static and every kind still agrees with brute force at any time.
//!
//! Ties between objects go to the lower object index, and inside an object to the lower triangle index,
//! so every structure kind gives the same hits as brute force at both levels. [`super::build`] makes
//! this geometry from a description.

use std::sync::Arc;
use std::time::Duration;

use crate::accel::{Accel, Hit, PrimHit, Primitives, TraversalCounts};
use crate::geometry::{Plane, Sphere, TriangleMesh};
use crate::math::{Aabb, Ray, Transform, Vec3};

mod summary;
mod sweep;

use sweep::BatchRays;

/// Scenes of at most this many bounded objects trace batches object by object
/// ([`SceneGeometry::intersect_many`]), every ray meeting every object's box ...
pub const SWEEP_OBJECTS: usize = 8;
/// ... when they hold this many triangles per object on average: a large mesh traced by a whole batch
/// (two rays at a time) gains more than the rays with no business in it cost, while small objects (a
/// Cornell box's walls) are cheaper left to the top level's boxes.
pub const SWEEP_MEAN_TRIANGLES: usize = 256;

/// A mesh in object space under its own structure; shared by every object that shows it.
pub struct MeshShape {
    /// Triangles in object space; `normals` are set for smooth shading only.
    pub mesh: TriangleMesh,
    /// The structure over `mesh`'s triangles.
    pub accel: Box<dyn Accel<TriangleMesh>>,
}

impl crate::light::EmitterMesh for MeshShape {
    fn mesh(&self) -> &TriangleMesh {
        &self.mesh
    }
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.accel.intersect(&self.mesh, ray, f32::INFINITY)
    }
}

/// What an object is made of.
#[derive(Clone)]
pub enum Shape {
    /// A triangle mesh (possibly shared with instances).
    Mesh(Arc<MeshShape>),
    /// A sphere (its transform is its own).
    Sphere(Sphere),
}

/// One bounded object of the runtime scene.
#[derive(Clone)]
pub struct SceneObject {
    /// Geometry.
    pub shape: Shape,
    /// Object to world for meshes (spheres carry theirs); `None` for the identity.
    pub transform: Option<Transform>,
    /// World-space translation over the shutter interval; `None` for a still object (tested once, not
    /// per ray).
    pub motion: Option<Vec3>,
    /// World-space bounds over the whole shutter interval.
    pub bounds: Aabb,
    /// Index into the description's objects.
    pub object: u32,
    /// Global index of the object's first primitive (for primitive ids across the whole scene).
    pub first_prim: u32,
}

impl SceneObject {
    /// The world ray relative to where the object is at the ray's time (same `t`).
    #[inline]
    fn still_ray(&self, ray: &Ray) -> Ray {
        still_ray(ray, self.motion)
    }

    /// The ray in object space at the ray's time (same `t` as in world space).
    #[inline]
    fn local_ray(&self, ray: &Ray) -> Ray {
        let ray = self.still_ray(ray);
        match &self.transform {
            None => ray,
            Some(t) => Ray::new(t.inv.transform_point3(ray.origin), t.inv.transform_vector3(ray.dir))
                .with_culling(ray.cull_backfaces)
                .with_time(ray.time),
        }
    }
}

/// How far an object moving by `motion` over the shutter interval has moved at `time`.
#[inline]
pub fn displacement(motion: Option<Vec3>, time: f32) -> Vec3 {
    motion.map_or(Vec3::ZERO, |m| m * time)
}

/// `ray` seen by an object moving by `motion` over the shutter interval, as if the object stood still
/// where it is at time 0: the ray moves back by the object's displacement at the ray's time.
#[inline]
pub(super) fn still_ray(ray: &Ray, motion: Option<Vec3>) -> Ray {
    match motion {
        None => *ray,
        Some(m) => Ray { origin: ray.origin - ray.time * m, ..*ray },
    }
}

/// An infinite plane of the scene: tested one by one after the hierarchy (it has no bounds).
#[derive(Debug, Clone, Copy)]
pub struct ScenePlane {
    /// The plane where it is at time 0.
    pub plane: Plane,
    /// Index into the description's objects.
    pub object: u32,
    /// World-space translation over the shutter interval; `None` for a still plane.
    pub motion: Option<Vec3>,
}

impl ScenePlane {
    #[inline]
    fn intersect(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        self.plane.intersect(&still_ray(ray, self.motion), t_max)
    }
}

/// The scene's bounded objects, as primitives of the top-level structure.
#[derive(Default)]
pub struct SceneObjects {
    /// Objects, in description order (planes excluded).
    pub objects: Vec<SceneObject>,
}

impl Primitives for SceneObjects {
    fn len(&self) -> usize {
        self.objects.len()
    }
    fn bounds(&self, i: usize) -> Aabb {
        self.objects[i].bounds
    }
    #[inline]
    fn intersect(&self, i: usize, ray: &Ray, t_max: f32) -> Option<PrimHit> {
        let o = &self.objects[i];
        match &o.shape {
            Shape::Mesh(m) => m.accel.intersect(&m.mesh, &o.local_ray(ray), t_max).map(nested),
            Shape::Sphere(s) => s.intersect(&o.still_ray(ray), t_max).map(|t| PrimHit::new(t, 0.0, 0.0)),
        }
    }
    fn occludes(&self, i: usize, ray: &Ray, t_max: f32) -> bool {
        let o = &self.objects[i];
        match &o.shape {
            Shape::Mesh(m) => m.accel.occluded(&m.mesh, &o.local_ray(ray), t_max),
            Shape::Sphere(s) => s.intersect(&o.still_ray(ray), t_max).is_some(),
        }
    }
    fn intersect_counted(&self, i: usize, ray: &Ray, t_max: f32, counts: &mut TraversalCounts) -> Option<PrimHit> {
        let o = &self.objects[i];
        match &o.shape {
            Shape::Mesh(m) => m.accel.intersect_counted(&m.mesh, &o.local_ray(ray), t_max, counts).map(nested),
            Shape::Sphere(s) => {
                counts.prims += 1;
                s.intersect(&o.still_ray(ray), t_max).map(|t| PrimHit::new(t, 0.0, 0.0))
            }
        }
    }
}

/// An object's hit as seen from the top level: the triangle becomes the sub-primitive.
#[inline]
fn nested(h: Hit) -> PrimHit {
    PrimHit { t: h.t, u: h.u, v: h.v, sub: h.prim }
}

/// What a scene holds, for summaries and `arbor info`.
#[derive(Debug, Clone, Default)]
pub struct SceneCounts {
    /// Triangles as rendered (an instanced mesh counts once per instance).
    pub triangles: usize,
    /// Triangles stored (each mesh once).
    pub unique_triangles: usize,
    /// Degenerate triangles among the stored ones (zero area: never hit).
    pub degenerate: usize,
    /// Spheres.
    pub spheres: usize,
    /// Infinite planes.
    pub planes: usize,
    /// Objects under the top-level structure.
    pub objects: usize,
    /// Time spent reading mesh files.
    pub mesh_load: Duration,
    /// Wall time from the loaded meshes to the finished structures: every mesh's (built in parallel,
    /// with its vertex normals), the object list and the top level's. Not the sum of the structures'
    /// own build times, which would count time once per thread that built in parallel.
    pub build: Duration,
}

/// The geometry of a scene under its two-level acceleration structure.
pub struct SceneGeometry {
    /// The bounded objects.
    pub objects: SceneObjects,
    /// The top-level structure over `objects`.
    pub top: Box<dyn Accel<SceneObjects>>,
    /// Every distinct mesh with its structure.
    pub meshes: Vec<Arc<MeshShape>>,
    /// Infinite planes.
    pub planes: Vec<ScenePlane>,
    /// Counts.
    pub counts: SceneCounts,
}

impl SceneGeometry {
    /// The closest hit of `ray` in `(0, t_max)`: `prim` is the object (planes come after the bounded
    /// objects), `sub` the triangle inside a mesh.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        if !ray.is_valid() {
            return None;
        }
        if self.planes.is_empty() {
            // The top level's hit returned as it is, not copied: the copy's wide loads of the callee's
            // narrower stores stalled the path tracer's every bounce.
            return self.top.intersect(&self.objects, ray, t_max);
        }
        let best = self.top.intersect(&self.objects, ray, t_max);
        self.intersect_planes(ray, t_max, best, None)
    }

    /// [`SceneGeometry::intersect`] for a batch (the camera rays of a few pixels): `out[i]` becomes
    /// `rays[i]`'s hit in `(0, t_max)`, the same hit as its own query.
    ///
    /// A scene of a few large meshes ([`SceneGeometry::sweeps`]) is swept object by object, each mesh
    /// tracing the rays of the batch that may meet its box (the box test of `sweep.rs`) together
    /// ([`Accel::intersect_many`]) up to the closest hit so far, which a later object must beat
    /// strictly (ties go to the lowest object, as at the top level); otherwise each ray walks the top
    /// level on its own. The box test across the batch is what the top level's walk would do for a
    /// ray: without it every ray paid a whole query of every object (in a Cornell box holding a large
    /// mesh, its walls took half the camera rays' instructions).
    ///
    /// # Panics
    /// When `rays` and `out` differ in length.
    pub fn intersect_many(&self, rays: &[Ray], t_max: f32, out: &mut [Option<Hit>]) {
        assert_eq!(rays.len(), out.len(), "a batch's rays and hits differ in length");
        if !self.sweeps() {
            for (o, r) in out.iter_mut().zip(rays) {
                *o = self.intersect(r, t_max);
            }
            return;
        }
        out.fill(None);
        let mut limit = vec![t_max; rays.len()];
        let (mut which, mut local, mut local_limit, mut found) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        // One object's own root box turns rays away as well as this test would.
        let mut batch = (self.objects.objects.len() > 1).then(|| BatchRays::new(rays));
        for (i, object) in self.objects.objects.iter().enumerate() {
            match &object.shape {
                Shape::Mesh(m) => {
                    // Only the rays that may meet the object's box before their closest hit so far,
                    // gathered when some may not.
                    which.clear();
                    if let Some(batch) = &mut batch {
                        batch.may_meet(&object.bounds, &limit, &mut which);
                    }
                    let all = batch.is_none() || which.len() == rays.len();
                    local.clear();
                    if all {
                        local.extend(rays.iter().map(|r| object.local_ray(r)));
                    } else {
                        local.extend(which.iter().map(|&j| object.local_ray(&rays[j as usize])));
                        local_limit.clear();
                        local_limit.extend(which.iter().map(|&j| limit[j as usize]));
                    }
                    found.clear();
                    found.resize(local.len(), None);
                    m.accel.intersect_many(&m.mesh, &local, if all { &limit } else { &local_limit }, &mut found);
                    for (k, h) in found.iter().enumerate() {
                        if let Some(h) = h {
                            let j = if all { k } else { which[k] as usize };
                            out[j] = Some(Hit::new(i as u32, nested(*h)));
                            limit[j] = h.t;
                        }
                    }
                }
                Shape::Sphere(_) => {
                    for ((o, l), r) in out.iter_mut().zip(&mut limit).zip(rays) {
                        if let Some(h) = self.objects.intersect(i, r, *l) {
                            *o = Some(Hit::new(i as u32, h));
                            *l = h.t;
                        }
                    }
                }
            }
        }
        // An invalid ray hits nothing, planes included, as in `intersect`.
        for (o, r) in out.iter_mut().zip(rays) {
            *o = if r.is_valid() { self.intersect_planes(r, t_max, *o, None) } else { None };
        }
    }

    /// [`SceneGeometry::intersect`] in `(0, inf)` for a batch of rays that go every way (a path
    /// tracer's bounces): `out[i]` becomes `rays[i]`'s hit, the same hit as its own query. The top level
    /// takes the whole batch ([`Accel::intersect_many`]: the BVH walks two rays at once, which hides
    /// the latency of one behind the other's).
    ///
    /// # Panics
    /// When `rays` and `out` differ in length.
    pub fn intersect_scattered(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        assert_eq!(rays.len(), out.len(), "a batch's rays and hits differ in length");
        // An invalid ray (a NaN) is never handed to a structure, as in `intersect`.
        if !rays.iter().all(Ray::is_valid) {
            for (o, r) in out.iter_mut().zip(rays) {
                *o = self.intersect(r, f32::INFINITY);
            }
            return;
        }
        let t_max = vec![f32::INFINITY; rays.len()];
        self.top.intersect_many(&self.objects, rays, &t_max, out);
        for (o, r) in out.iter_mut().zip(rays) {
            *o = self.intersect_planes(r, f32::INFINITY, *o, None);
        }
    }

    /// [`SceneGeometry::occluded`] for a batch: `out[i]` becomes whether anything lies on `rays[i]` in
    /// `(0, t_max[i])`, through the top level's batched query.
    ///
    /// # Panics
    /// When `rays`, `t_max` and `out` differ in length.
    pub fn occluded_many(&self, rays: &[Ray], t_max: &[f32], out: &mut [bool]) {
        assert!(
            rays.len() == t_max.len() && rays.len() == out.len(),
            "a batch's rays, t_max and answers differ in length"
        );
        if !rays.iter().all(Ray::is_valid) {
            for ((o, r), &t) in out.iter_mut().zip(rays).zip(t_max) {
                *o = self.occluded(r, t);
            }
            return;
        }
        self.top.occluded_many(&self.objects, rays, t_max, out);
        for ((o, r), &t) in out.iter_mut().zip(rays).zip(t_max) {
            *o = *o || self.plane_blocks(r, t);
        }
    }

    /// Whether [`SceneGeometry::intersect_many`] sweeps the objects: one, or a few large ones
    /// ([`SWEEP_OBJECTS`]).
    pub fn sweeps(&self) -> bool {
        let n = self.objects.objects.len();
        n == 1 || (n <= SWEEP_OBJECTS && self.counts.triangles >= n * SWEEP_MEAN_TRIANGLES)
    }

    /// [`SceneGeometry::intersect`], adding the nodes visited and primitives tested at both levels to
    /// `counts` (the traversal-cost heatmap).
    pub fn intersect_counted(&self, ray: &Ray, t_max: f32, counts: &mut TraversalCounts) -> Option<Hit> {
        if !ray.is_valid() {
            return None;
        }
        let best = self.top.intersect_counted(&self.objects, ray, t_max, counts);
        self.intersect_planes(ray, t_max, best, Some(counts))
    }

    fn intersect_planes(
        &self,
        ray: &Ray,
        t_max: f32,
        mut best: Option<Hit>,
        mut counts: Option<&mut TraversalCounts>,
    ) -> Option<Hit> {
        let base = self.objects.len() as u32;
        for (k, plane) in self.planes.iter().enumerate() {
            if let Some(c) = counts.as_deref_mut() {
                c.prims += 1;
            }
            if let Some(t) = plane.intersect(ray, best.map_or(t_max, |h| h.t)) {
                best = Some(Hit { t, prim: base + k as u32, u: 0.0, v: 0.0, sub: 0 });
            }
        }
        best
    }

    /// Whether anything lies on `ray` in `(0, t_max)`.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        ray.is_valid() && (self.plane_blocks(ray, t_max) || self.top.occluded(&self.objects, ray, t_max))
    }

    /// Whether an infinite plane lies on `ray` in `(0, t_max)`.
    fn plane_blocks(&self, ray: &Ray, t_max: f32) -> bool {
        self.planes.iter().any(|p| p.intersect(ray, t_max).is_some())
    }

    /// A scene-wide id of the primitive hit (triangle, sphere or plane), the same for every structure.
    pub fn global_prim_id(&self, hit: &Hit) -> u32 {
        match self.objects.objects.get(hit.prim as usize) {
            Some(o) => o.first_prim + hit.sub,
            None => {
                let bounded = self.objects.objects.last().map_or(0, |o| o.first_prim + prim_count(&o.shape));
                bounded + (hit.prim - self.objects.len() as u32)
            }
        }
    }

    /// Whether anything moves over the shutter interval.
    pub fn has_motion(&self) -> bool {
        self.objects.objects.iter().any(|o| o.motion.is_some()) || self.planes.iter().any(|p| p.motion.is_some())
    }

    /// Bounds of the bounded objects.
    pub fn bounds(&self) -> Aabb {
        self.top.bounds()
    }
}

/// Primitives of one object: its triangles, or 1 for a sphere.
pub(super) fn prim_count(shape: &Shape) -> u32 {
    match shape {
        Shape::Mesh(m) => m.mesh.len() as u32,
        Shape::Sphere(_) => 1,
    }
}

/// The world box of an object-space box.
pub(super) fn world_box(b: &Aabb, t: Option<&Transform>) -> Aabb {
    let Some(t) = t else { return *b };
    (0..8).fold(Aabb::EMPTY, |acc, i| {
        let corner = Vec3::new(
            if i & 1 == 0 { b.min.x } else { b.max.x },
            if i & 2 == 0 { b.min.y } else { b.max.y },
            if i & 4 == 0 { b.min.z } else { b.max.z },
        );
        acc.grow(t.point(corner))
    })
}
