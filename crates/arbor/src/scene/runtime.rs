//! The runtime scene: the description, its geometry under an acceleration structure, and the
//! environment map; plus the shading data of a hit, computed once from the final [`Hit`] only (the
//! structures never touch normals or materials).

use std::time::{Duration, Instant};

use super::build::build_geometry;
use super::desc::{MaterialDesc, OffsetRule, SceneDesc};
use super::geometry::{SceneGeometry, Shape};
use crate::accel::{AccelSpec, Hit};
use crate::geometry::error_bound::{plane_point, sphere_point, transform_point, triangle_point};
use crate::geometry::TriangleMesh;
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
    /// World-space point: `o + t d` under [`OffsetRule::ShadowEpsilon`]; recomputed from the surface's
    /// own parameters (barycentrics, reprojection) under [`OffsetRule::ErrorBound`].
    pub p: Vec3,
    /// Per-component bound on the error of `p` under [`OffsetRule::ErrorBound`] (zero otherwise).
    pub p_error: Vec3,
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
                        desc.environment_loc.clone().unwrap_or_else(|| Location::file(&desc.source)),
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
        let g = &self.geometry;
        let mut p = ray.at(hit.t);
        let mut p_error = Vec3::ZERO;
        let bound = self.desc.offset == OffsetRule::ErrorBound;
        let (ng, ns, object) = match g.objects.objects.get(hit.prim as usize) {
            Some(o) => {
                let (ng, ns) = match &o.shape {
                    Shape::Mesh(m) => {
                        if bound {
                            let (q, e) = triangle_point(m.mesh.triangle(hit.sub as usize), hit.u, hit.v);
                            (p, p_error) = match &o.transform {
                                None => (q, e),
                                Some(t) => transform_point(t, q, e),
                            };
                        }
                        let (ng, ns) = triangle_normals(&m.mesh, hit);
                        match &o.transform {
                            None => (ng, ns),
                            Some(t) => {
                                let nm = t.normal_matrix();
                                let ng = (nm * ng).normalize_or_zero();
                                (ng, (nm * ns).normalize_or(ng))
                            }
                        }
                    }
                    Shape::Sphere(s) => {
                        if bound {
                            let local = if s.transform.is_identity() { p } else { s.transform.inv.transform_point3(p) };
                            let (q, e) = sphere_point(local, s.center, s.radius);
                            (p, p_error) =
                                if s.transform.is_identity() { (q, e) } else { transform_point(&s.transform, q, e) };
                        }
                        let n = s.normal_at(p);
                        (n, n)
                    }
                };
                (ng, ns, o.object)
            }
            None => {
                let (plane, object) = &g.planes[hit.prim as usize - g.objects.objects.len()];
                if bound {
                    (p, p_error) = plane_point(p, plane.point, plane.normal);
                }
                (plane.normal, plane.normal, *object)
            }
        };
        Surface { p, p_error, ng, ns, object, material: self.desc.objects[object as usize].material }
    }
}

/// Object-space geometric and shading normals of the triangle `hit.sub` of `mesh`: the shading normal
/// interpolates the vertex normals of smooth meshes.
fn triangle_normals(mesh: &TriangleMesh, hit: &Hit) -> (Vec3, Vec3) {
    let i = hit.sub as usize;
    let [a, b, c] = mesh.triangle(i);
    let ng = (b - a).cross(c - a).normalize_or_zero();
    let ns = match &mesh.normals {
        Some(n) => {
            let [ia, ib, ic] = mesh.indices[i];
            let interpolated = (1.0 - hit.u - hit.v) * n[ia as usize] + hit.u * n[ib as usize] + hit.v * n[ic as usize];
            interpolated.normalize_or(ng)
        }
        None => ng,
    };
    (ng, ns)
}
