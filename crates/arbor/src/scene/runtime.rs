//! The runtime scene: the description, its geometry under an acceleration structure, and the
//! environment map; plus the shading data of a hit, computed once from the final [`Hit`] only (the
//! structures never touch normals or materials).

use std::time::{Duration, Instant};

use super::build::{build_geometry, SceneGeometry};
use super::desc::{MaterialDesc, SceneDesc};
use crate::accel::{AccelSpec, Hit};
use crate::light::environment::EnvMap;
use crate::math::{Ray, Vec3};
use crate::{Error, Location, Result};

/// A scene ready to render.
pub struct Scene {
    /// What the file said.
    pub desc: SceneDesc,
    /// World-space primitives under an acceleration structure.
    pub geometry: SceneGeometry,
    /// Seen by rays that miss, when the scene or the user names one.
    pub environment: Option<EnvMap>,
    /// Wall time of the structure's build (mesh loading excluded).
    pub build_time: Duration,
}

/// The shading data at a hit.
#[derive(Debug, Clone, Copy)]
pub struct Surface {
    /// World-space point.
    pub p: Vec3,
    /// Unit geometric normal, outward (counter-clockwise side for triangles).
    pub ng: Vec3,
    /// Unit shading normal (interpolated for smooth meshes), on the same side as `ng`.
    pub ns: Vec3,
    /// Index into the description's objects.
    pub object: u32,
    /// Index into the description's materials.
    pub material: usize,
}

impl Scene {
    /// Loads the meshes and builds the structure. `environment` overrides the scene's own map.
    pub fn build(desc: SceneDesc, spec: &AccelSpec, environment: Option<EnvMap>) -> Result<Scene> {
        let environment = match environment {
            Some(env) => Some(env),
            None => match desc.environment.as_deref() {
                None => None,
                // A map the scene names but that cannot be read is the scene's fault, like a missing mesh.
                Some(path) => Some(EnvMap::load(path).map_err(|e| match e {
                    Error::Io { source, .. } => Error::input(
                        Location::file(&desc.source),
                        format!("cannot read environment map '{}': {source}", path.display()),
                    ),
                    other => other,
                })?),
            },
        };
        let start = Instant::now();
        let geometry = build_geometry(&desc, spec)?;
        let build_time = start.elapsed().saturating_sub(geometry.counts.mesh_load);
        Ok(Scene { desc, geometry, environment, build_time })
    }

    /// The material of a surface.
    #[inline]
    pub fn material(&self, s: &Surface) -> &MaterialDesc {
        &self.desc.materials[s.material]
    }

    /// Shading data for `hit`, found on `ray`.
    pub fn surface(&self, ray: &Ray, hit: &Hit) -> Surface {
        let prims = &self.geometry.prims;
        let p = ray.at(hit.t);
        let i = hit.prim as usize;
        let n_tris = prims.triangles.len();
        let n_bounded = n_tris + prims.spheres.len();
        let (ng, ns, object) = if i < n_tris {
            let [a, b, c] = prims.triangle(i);
            let ng = (b - a).cross(c - a).normalize_or_zero();
            let [ia, ib, ic] = prims.triangles[i];
            let (na, nb, nc) = (prims.normals[ia as usize], prims.normals[ib as usize], prims.normals[ic as usize]);
            let ns = if na == Vec3::ZERO || nb == Vec3::ZERO || nc == Vec3::ZERO {
                ng
            } else {
                ((1.0 - hit.u - hit.v) * na + hit.u * nb + hit.v * nc).normalize_or(ng)
            };
            (ng, ns, prims.triangle_object[i])
        } else if i < n_bounded {
            let s = i - n_tris;
            let n = prims.spheres[s].normal_at(p);
            (n, n, prims.sphere_object[s])
        } else {
            let (plane, object) = &self.geometry.planes[i - n_bounded];
            (plane.normal, plane.normal, *object)
        };
        let object_desc = &self.desc.objects[object as usize];
        Surface { p, ng, ns, object, material: object_desc.material }
    }
}
