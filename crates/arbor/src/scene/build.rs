//! From description to runtime scene: loads mesh files (in parallel, each file once), takes every
//! object to world space, and builds one acceleration structure over all bounded primitives
//! (triangles, then spheres). Infinite planes stay outside the hierarchy and are tested one by one.
//!
//! Instances are expanded into copies of their base geometry for now; the two-level scene with shared
//! geometry comes with the full set of structures.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use rayon::prelude::*;

use super::desc::{MeshSource, ObjectDesc, SceneDesc, ShapeDesc};
use crate::accel::{self, Accel, AccelSpec, AccelStats, Hit, PrimHit, Primitives, TraversalCounts};
use crate::geometry::{intersect_triangle, Plane, Sphere, TriangleMesh};
use crate::math::{Aabb, Ray, Vec3};
use crate::{Error, Result};

/// Every bounded primitive of a scene in world space: triangles first, then spheres.
#[derive(Debug, Default)]
pub struct ScenePrims {
    /// All meshes' vertices, world space.
    pub positions: Vec<Vec3>,
    /// Per-vertex shading normals, world space (zero for vertices of flat-shaded meshes).
    pub normals: Vec<Vec3>,
    /// Triangles as indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
    /// For each triangle, the object it belongs to.
    pub triangle_object: Vec<u32>,
    /// Spheres.
    pub spheres: Vec<Sphere>,
    /// For each sphere, the object it belongs to.
    pub sphere_object: Vec<u32>,
}

impl ScenePrims {
    /// The corners of triangle `i`.
    #[inline]
    pub fn triangle(&self, i: usize) -> [Vec3; 3] {
        let [a, b, c] = self.triangles[i];
        [self.positions[a as usize], self.positions[b as usize], self.positions[c as usize]]
    }
}

impl Primitives for ScenePrims {
    fn len(&self) -> usize {
        self.triangles.len() + self.spheres.len()
    }
    fn bounds(&self, i: usize) -> Aabb {
        match i.checked_sub(self.triangles.len()) {
            None => Aabb::from_points(self.triangle(i)),
            Some(s) => self.spheres[s].bounds(),
        }
    }
    #[inline]
    fn intersect(&self, i: usize, ray: &Ray, t_max: f32) -> Option<PrimHit> {
        match i.checked_sub(self.triangles.len()) {
            None => {
                let [a, b, c] = self.triangle(i);
                intersect_triangle(ray, a, b, c, t_max).map(|h| PrimHit { t: h.t, u: h.b1, v: h.b2 })
            }
            Some(s) => self.spheres[s].intersect(ray, t_max).map(|t| PrimHit { t, u: 0.0, v: 0.0 }),
        }
    }
}

/// What a scene holds, for summaries and `arbor info`.
#[derive(Debug, Clone, Default)]
pub struct SceneCounts {
    /// Triangles (after instancing).
    pub triangles: usize,
    /// Degenerate triangles among them (zero area: never hit).
    pub degenerate: usize,
    /// Spheres.
    pub spheres: usize,
    /// Infinite planes.
    pub planes: usize,
    /// Time spent reading mesh files.
    pub mesh_load: Duration,
}

/// The geometry of a scene under its acceleration structure.
pub struct SceneGeometry {
    /// Bounded primitives.
    pub prims: ScenePrims,
    /// The structure over `prims`.
    pub accel: Box<dyn Accel<ScenePrims>>,
    /// Infinite planes and their objects.
    pub planes: Vec<(Plane, u32)>,
    /// Counts.
    pub counts: SceneCounts,
}

impl SceneGeometry {
    /// The closest hit of `ray` in `(0, t_max)`. Plane hits get primitive indices after all bounded
    /// primitives.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        if !ray.is_valid() {
            return None;
        }
        let mut best = self.accel.intersect(&self.prims, ray, t_max);
        let base = self.prims.len() as u32;
        for (k, (plane, _)) in self.planes.iter().enumerate() {
            let limit = best.map_or(t_max, |h| h.t);
            if let Some(t) = plane.intersect(ray, limit) {
                best = Some(Hit { t, prim: base + k as u32, u: 0.0, v: 0.0 });
            }
        }
        best
    }

    /// [`SceneGeometry::intersect`], adding the nodes visited and primitives tested to `counts` (the
    /// traversal-cost heatmap).
    pub fn intersect_counted(&self, ray: &Ray, t_max: f32, counts: &mut TraversalCounts) -> Option<Hit> {
        if !ray.is_valid() {
            return None;
        }
        let mut best = self.accel.intersect_counted(&self.prims, ray, t_max, counts);
        let base = self.prims.len() as u32;
        for (k, (plane, _)) in self.planes.iter().enumerate() {
            counts.prims += 1;
            let limit = best.map_or(t_max, |h| h.t);
            if let Some(t) = plane.intersect(ray, limit) {
                best = Some(Hit { t, prim: base + k as u32, u: 0.0, v: 0.0 });
            }
        }
        best
    }

    /// The world-space boxes of the structure's nodes at `depth` (the boxes debug view).
    pub fn boxes_at_depth(&self, depth: usize) -> Vec<Aabb> {
        self.accel.boxes_at_depth(depth)
    }

    /// Whether anything lies on `ray` in `(0, t_max)`.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        ray.is_valid()
            && (self.planes.iter().any(|(p, _)| p.intersect(ray, t_max).is_some())
                || self.accel.occluded(&self.prims, ray, t_max))
    }

    /// The acceleration structure's statistics.
    pub fn accel_stats(&self) -> AccelStats {
        self.accel.stats()
    }

    /// Bounds of the bounded primitives.
    pub fn bounds(&self) -> Aabb {
        self.accel.bounds()
    }
}

/// Loads the meshes of `desc` and builds its geometry under the structure `spec` describes.
pub fn build_geometry(desc: &SceneDesc, spec: &AccelSpec) -> Result<SceneGeometry> {
    let start = Instant::now();
    let meshes = load_mesh_files(desc)?;
    let mesh_load = start.elapsed();

    let mut prims = ScenePrims::default();
    let mut planes = Vec::new();
    for (index, object) in desc.objects.iter().enumerate() {
        let (shape_object, transform) = match object.shape {
            ShapeDesc::Instance { base } => (resolve_instance(desc, index, base)?, object.transform),
            _ => (object, object.transform),
        };
        let id = index as u32;
        match &shape_object.shape {
            ShapeDesc::Mesh { source, smooth } => {
                let mesh = match source {
                    MeshSource::Inline(m) => m.clone(),
                    MeshSource::File(path) => meshes[path].clone(),
                };
                add_mesh(&mut prims, &mesh.transformed(&transform), *smooth, id);
            }
            ShapeDesc::Sphere { center, radius } => {
                prims.spheres.push(Sphere { center: *center, radius: *radius, transform });
                prims.sphere_object.push(id);
            }
            ShapeDesc::Plane { point, normal } => {
                let point = transform.point(*point);
                let normal = transform.normal(*normal).normalize();
                planes.push((Plane { point, normal }, id));
            }
            ShapeDesc::Instance { .. } => unreachable!("resolve_instance never returns an instance"),
        }
    }
    let degenerate = (0..prims.triangles.len())
        .filter(|&i| {
            let [a, b, c] = prims.triangle(i);
            (b - a).cross(c - a).length_squared() == 0.0
        })
        .count();
    let counts = SceneCounts {
        triangles: prims.triangles.len(),
        degenerate,
        spheres: prims.spheres.len(),
        planes: planes.len(),
        mesh_load,
    };
    let accel = accel::build_with(spec, &prims).map_err(Error::Invalid)?;
    Ok(SceneGeometry { prims, accel, planes, counts })
}

/// The object an instance draws its geometry from (following chains of instances).
fn resolve_instance(desc: &SceneDesc, index: usize, mut base: usize) -> Result<&ObjectDesc> {
    for _ in 0..desc.objects.len() {
        let object = desc.objects.get(base).ok_or_else(|| {
            Error::input(
                desc.objects[index].loc.clone(),
                format!("{}: base object does not exist", desc.objects[index].name),
            )
        })?;
        match object.shape {
            ShapeDesc::Instance { base: next } => base = next,
            _ => return Ok(object),
        }
    }
    Err(Error::input(
        desc.objects[index].loc.clone(),
        format!("{}: instances refer to each other in a cycle", desc.objects[index].name),
    ))
}

/// Reads every distinct mesh file once, in parallel. A failure names the object that asked for the file.
fn load_mesh_files(desc: &SceneDesc) -> Result<HashMap<PathBuf, Arc<TriangleMesh>>> {
    let mut wanted: Vec<(&PathBuf, &ObjectDesc)> = Vec::new();
    for object in &desc.objects {
        if let ShapeDesc::Mesh { source: MeshSource::File(path), .. } = &object.shape {
            if !wanted.iter().any(|(p, _)| *p == path) {
                wanted.push((path, object));
            }
        }
    }
    wanted
        .par_iter()
        .map(|(path, object)| {
            let mesh = crate::mesh_io::load_mesh(path).map_err(|e| match e {
                Error::Io { source, .. } => Error::input(
                    object.loc.clone(),
                    format!("{}: cannot read mesh file '{}': {source}", object.name, path.display()),
                ),
                other => other,
            })?;
            Ok(((*path).clone(), Arc::new(mesh)))
        })
        .collect()
}

/// Appends a world-space mesh. Smooth meshes get vertex normals (from the file, or averaged from the
/// faces); flat ones get zero normals, which tells the shader to use the face normal.
fn add_mesh(prims: &mut ScenePrims, mesh: &TriangleMesh, smooth: bool, object: u32) {
    let offset = prims.positions.len() as u32;
    prims.positions.extend_from_slice(&mesh.positions);
    if smooth {
        let normals = match &mesh.normals {
            Some(n) => n.iter().map(|n| n.normalize_or_zero()).collect(),
            None => {
                let mut m = mesh.clone();
                m.compute_vertex_normals();
                m.normals.unwrap_or_default()
            }
        };
        prims.normals.extend(normals);
    } else {
        prims.normals.extend(std::iter::repeat(Vec3::ZERO).take(mesh.positions.len()));
    }
    prims.triangles.extend(mesh.indices.iter().map(|t| t.map(|i| i + offset)));
    prims.triangle_object.extend(std::iter::repeat(object).take(mesh.indices.len()));
}
