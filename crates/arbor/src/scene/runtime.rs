//! The runtime scene: geometry under its acceleration structures ([`super::geometry`]), materials,
//! lights, cameras, the environment map and the settings shading needs, all in runtime types (the build
//! step, [`super::build`], makes them from a description; nothing here reads the description); plus the
//! shading data of a hit, computed once from the final [`Hit`] only (the structures never touch normals
//! or materials).

use std::time::Duration;

use super::geometry::{displacement, SceneGeometry, ScenePlane, Shape};
use crate::accel::Hit;
use crate::camera::{Camera, RayCone};
use crate::geometry::error_bound::{plane_point, sphere_point, transform_point, triangle_point};
use crate::geometry::TriangleMesh;
use crate::light::environment::EnvMap;
use crate::light::Light;
use crate::material::{Material, DEGAMMA};
use crate::math::{Color, Ray, Transform, Vec2, Vec3};
use crate::texture::{self, Shaded, TexPoint, Texture};

/// A scene ready to render.
pub struct Scene {
    /// World-space primitives under an acceleration structure.
    pub geometry: SceneGeometry,
    /// Materials; [`Scene::object_materials`] says which object has which.
    pub materials: Vec<Material>,
    /// The index into [`Scene::materials`] of each object, in scene-file order (the `object` of a
    /// [`Surface`]).
    pub object_materials: Vec<usize>,
    /// Texture maps; [`Scene::object_textures`] says which object has which.
    pub textures: Vec<Texture>,
    /// The indices into [`Scene::textures`] of each object's maps, in scene-file order (mostly empty).
    pub object_textures: Vec<Vec<usize>>,
    /// Whether some map reads a hit's footprint ([`Texture::wants_footprint`]); if none does, no hit
    /// works one out.
    pub footprints: bool,
    /// The texture that replaces the background of camera rays that miss, spanning the image plane.
    pub background_texture: Option<usize>,
    /// Lights other than the ambient light and the environment; emissive objects' lights come last.
    pub lights: Vec<Box<dyn Light>>,
    /// The index into [`Scene::lights`] of the environment map's light, when the scene names one (an
    /// environment given only on the command line lights the misses without being sampled).
    pub environment_light: Option<usize>,
    /// For each object, in scene-file order, the index into [`Scene::lights`] of the light it is
    /// ([`Scene::light_of`]).
    pub object_lights: Vec<Option<usize>>,
    /// For each object, in scene-file order, the radiance it emits from its front side, if any
    /// ([`Scene::emitted`]).
    pub object_emission: Vec<Option<Color>>,
    /// One image per camera.
    pub cameras: Vec<Camera>,
    /// Seen by rays that miss, when the scene or the user names one.
    pub environment: Option<EnvMap>,
    /// Radiance of camera rays that hit nothing (and have no environment map).
    pub background: Color,
    /// Ambient radiance, added as `ambient reflectance * ambient` everywhere, shadowed or not.
    pub ambient: Color,
    /// Multiplies the scene's radiance to get display units (1.0 = white).
    pub radiance_scale: f32,
    /// Bounces of specular rays; 0 means none.
    pub max_depth: u32,
    /// Whether lights are tested for occlusion.
    pub shadows: bool,
    /// Whether a surface hit from behind has its normals turned towards the ray; if not, it is shaded,
    /// and its shadow and mirror rays leave, on the side of its stored normal.
    pub flip_back_faces: bool,
    /// Back-face culling of camera rays as the scene (`BackfaceCulling`) or its form (the 2025 METU JSON
    /// form culls) asks for it, if either makes a choice.
    pub cull_backfaces: Option<bool>,
    /// Where secondary rays start.
    pub offset: RayOffset,
    /// Wall time of the structures' build (mesh loading excluded).
    pub build_time: Duration,
}

/// How far secondary rays (shadow, reflected, refracted) start from the surface they leave.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RayOffset {
    /// By this distance along the geometric normal (the METU formats' `ShadowRayEpsilon`; their
    /// reference images depend on it).
    ShadowEpsilon(f32),
    /// By the floating-point error bound of the hit point (pbrt-v4's `OffsetRayOrigin`,
    /// [`crate::geometry::error_bound`]), for scenes that give no epsilon.
    ErrorBound,
}

/// The shading data at a hit.
#[derive(Debug, Clone, Copy)]
pub struct Surface {
    /// World-space point: `o + t d` under [`RayOffset::ShadowEpsilon`]; recomputed from the surface's
    /// own parameters (barycentrics, reprojection) under [`RayOffset::ErrorBound`].
    pub p: Vec3,
    /// Per-component bound on the error of `p` under [`RayOffset::ErrorBound`] (zero otherwise).
    pub p_error: Vec3,
    /// Unit geometric normal, outward (counter-clockwise side for triangles).
    pub ng: Vec3,
    /// Unit shading normal (interpolated for smooth meshes), on the same side as `ng`.
    pub ns: Vec3,
    /// Index of the object hit, in scene-file order.
    pub object: u32,
    /// Index into [`Scene::materials`].
    pub material: usize,
}

impl Scene {
    /// The material of a surface.
    #[inline]
    pub fn material(&self, s: &Surface) -> &Material {
        &self.materials[s.material]
    }

    /// The radiance leaving the surface point `s` towards `wo` (either length): its object's emission
    /// on the side its geometric normal points to (the front of a light mesh's triangles, the outside
    /// of a light sphere), zero on the other side and for objects that do not emit.
    #[inline]
    pub fn emitted(&self, s: &Surface, wo: Vec3) -> Color {
        match self.object_emission.get(s.object as usize) {
            Some(Some(radiance)) if wo.dot(s.ng) > 0.0 => *radiance,
            _ => Color::ZERO,
        }
    }

    /// Whether object `object` (scene-file order) has texture maps ([`Scene::textured`] changes its
    /// shading).
    #[inline]
    pub fn has_textures(&self, object: u32) -> bool {
        self.object_textures.get(object as usize).is_some_and(|t| !t.is_empty())
    }

    /// The index into [`Scene::lights`] of the light that object `object` (scene-file order) is, if it
    /// emits.
    #[inline]
    pub fn light_of(&self, object: u32) -> Option<usize> {
        self.object_lights.get(object as usize).copied().flatten()
    }

    /// Shading data for `hit`, found on `ray`.
    #[inline]
    pub fn surface(&self, ray: &Ray, hit: &Hit) -> Surface {
        let g = &self.geometry;
        let mut p = ray.at(hit.t);
        let mut p_error = Vec3::ZERO;
        let bound = self.offset == RayOffset::ErrorBound;
        let (ng, ns, object) = match g.objects.objects.get(hit.prim as usize) {
            Some(o) => {
                // Where a moving object is at the ray's time; shapes below are placed at time 0.
                let shift = displacement(o.motion, ray.time);
                let (ng, ns) = match &o.shape {
                    Shape::Mesh(m) => {
                        if bound {
                            let (q, e) = triangle_point(m.mesh.triangle(hit.sub as usize), hit.u, hit.v);
                            (p, p_error) = match &o.transform {
                                None => (q, e),
                                Some(t) => transform_point(t, q, e),
                            };
                            p += shift;
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
                            let still = p - shift;
                            let local =
                                if s.transform.is_identity() { still } else { s.transform.inv.transform_point3(still) };
                            let (q, e) = sphere_point(local, s.center, s.radius);
                            (p, p_error) =
                                if s.transform.is_identity() { (q, e) } else { transform_point(&s.transform, q, e) };
                            p += shift;
                        }
                        let n = s.normal_at(p - shift);
                        (n, n)
                    }
                };
                (ng, ns, o.object)
            }
            None => {
                let ScenePlane { plane, object, motion } = g.planes[hit.prim as usize - g.objects.objects.len()];
                if bound {
                    let shift = displacement(motion, ray.time);
                    (p, p_error) = plane_point(p - shift, plane.point, plane.normal);
                    p += shift;
                }
                (plane.normal, plane.normal, object)
            }
        };
        Surface { p, p_error, ng, ns, object, material: self.object_materials[object as usize] }
    }
}

impl Scene {
    /// The Blinn-Phong terms of `s` after its object's textures, with `s.ns` replaced by the textured
    /// normal (in world space); `None`, and `s` unchanged, for an object without textures. `cone` is the
    /// ray's, for the footprint that trilinear maps filter over.
    pub fn textured(&self, ray: &Ray, hit: &Hit, s: &mut Surface, cone: RayCone) -> Option<Shaded> {
        let maps = self.object_textures.get(s.object as usize).filter(|t| !t.is_empty())?;
        let (mut at, to_world) = self.tex_point(ray, hit, s);
        if self.footprints && maps.iter().any(|&i| self.textures[i].wants_footprint()) {
            let width = cone.width_at(hit.t * ray.dir.length());
            at.footprint = footprint(width, ray.dir, s.ng, &at, to_world.as_ref());
        }
        let m = self.material(s);
        let base = Shaded { ambient: m.ambient, diffuse: m.diffuse, specular: m.specular, n: at.n, replace_all: None };
        let degamma = m.degamma.then_some(DEGAMMA);
        let out = texture::apply(maps.iter().map(|&i| &self.textures[i]), base, &at, degamma);
        if out.n != at.n {
            let n = match to_world {
                Some(t) => t.normal(out.n).normalize_or(s.ns),
                None => out.n,
            };
            s.ns = if n.dot(s.ng) * s.ns.dot(s.ng) < 0.0 { -n } else { n };
        }
        Some(out)
    }

    /// The sampling point of a hit in its texture frame ([`TexPoint`]) and the transform from that frame
    /// to world space (`None` for the identity).
    fn tex_point(&self, ray: &Ray, hit: &Hit, s: &Surface) -> (TexPoint, Option<Transform>) {
        let still = |motion| s.p - displacement(motion, ray.time);
        match self.geometry.objects.objects.get(hit.prim as usize) {
            Some(o) => match &o.shape {
                Shape::Mesh(m) => {
                    let mesh = &m.mesh;
                    let i = hit.sub as usize;
                    let [a, b, c] = mesh.triangle(i);
                    let w = Vec3::new(1.0 - hit.u - hit.v, hit.u, hit.v);
                    let p = w.x * a + w.y * b + w.z * c;
                    let (_, n) = triangle_normals(mesh, hit);
                    let (uv, dpdu, dpdv) = match &mesh.uvs {
                        Some(uvs) => {
                            let [ia, ib, ic] = mesh.indices[i].map(|k| uvs[k as usize]);
                            let uv = w.x * ia + w.y * ib + w.z * ic;
                            let (d1, d2) = (ib - ia, ic - ia);
                            let (e1, e2) = (b - a, c - a);
                            let det = d1.x * d2.y - d2.x * d1.y;
                            let inv = if det.abs() > f32::MIN_POSITIVE { 1.0 / det } else { 0.0 };
                            (uv, (d2.y * e1 - d1.y * e2) * inv, (d1.x * e2 - d2.x * e1) * inv)
                        }
                        None => (Vec2::ZERO, Vec3::ZERO, Vec3::ZERO),
                    };
                    (TexPoint { uv, p, n, dpdu, dpdv, footprint: 0.0 }, o.transform)
                }
                Shape::Sphere(sp) => {
                    // In world space (see TexPoint): (u, v) from the sphere's own point, its tangents
                    // carried by the transform, its normal by the inverse transpose.
                    let world = still(o.motion);
                    let at = if sp.transform.is_identity() {
                        sphere_tex_point(world, sp.center, sp.radius)
                    } else {
                        let t = &sp.transform;
                        let local = sphere_tex_point(t.inv.transform_point3(world), sp.center, sp.radius);
                        TexPoint {
                            p: world,
                            n: t.normal(local.n).normalize_or(s.ns),
                            dpdu: t.vector(local.dpdu),
                            dpdv: t.vector(local.dpdv),
                            ..local
                        }
                    };
                    (at, None)
                }
            },
            None => {
                let plane = &self.geometry.planes[hit.prim as usize - self.geometry.objects.objects.len()];
                let (p, n) = (still(plane.motion), plane.plane.normal);
                (TexPoint { uv: Vec2::ZERO, p, n, dpdu: Vec3::ZERO, dpdv: Vec3::ZERO, footprint: 0.0 }, None)
            }
        }
    }
}

/// Spherical texture coordinates of the point `p` of a sphere (CENG 795): with `r = p - center`,
/// `u = (π - atan2(r.z, r.x)) / 2π`, `v = acos(r.y / radius) / π`; and the derivatives of `p` along them.
fn sphere_tex_point(p: Vec3, center: Vec3, radius: f32) -> TexPoint {
    use std::f32::consts::PI;
    let r = p - center;
    let theta = (r.y / radius).clamp(-1.0, 1.0).acos();
    let phi = r.z.atan2(r.x);
    let uv = Vec2::new((PI - phi) / (2.0 * PI), theta / PI);
    let dpdu = 2.0 * PI * Vec3::new(r.z, 0.0, -r.x);
    let dpdv = PI * Vec3::new(r.y * phi.cos(), -radius * theta.sin(), r.y * phi.sin());
    TexPoint { uv, p, n: (r / radius).normalize_or(Vec3::Y), dpdu, dpdv, footprint: 0.0 }
}

/// The side in (u, v) units of a ray cone `width` wide meeting a surface of unit normal `ng` along `dir`
/// at `at` (Akenine-Möller et al. 2019): the cone's width over `|cos θ|`, times the surface's texel
/// density `1 / sqrt(|∂p/∂u × ∂p/∂v|)` in world space (for a triangle, the square root of its (u, v)
/// area over its world area). 0, the finest level, where the derivatives are not known (no (u, v),
/// a sphere's poles); at grazing angles, past every level.
fn footprint(width: f32, dir: Vec3, ng: Vec3, at: &TexPoint, to_world: Option<&Transform>) -> f32 {
    let (du, dv) = match to_world {
        Some(t) => (t.vector(at.dpdu), t.vector(at.dpdv)),
        None => (at.dpdu, at.dpdv),
    };
    let area = du.cross(dv).length();
    if area > 0.0 {
        let cos = dir.normalize_or_zero().dot(ng).abs();
        width / (cos * area.sqrt())
    } else {
        0.0
    }
}

/// Object-space geometric and shading normals of the triangle `hit.sub` of `mesh`: the shading normal
/// interpolates the vertex normals of smooth meshes.
#[inline(always)]
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn footprint_is_the_cone_width_in_uv_units_stretched_by_the_angle() {
        // A plane with u = x / 4, v = y / 2 (∂p/∂u = 4x, ∂p/∂v = 2y): sqrt(8) world units per (u, v) unit.
        let at = TexPoint {
            uv: Vec2::ZERO,
            p: Vec3::ZERO,
            n: Vec3::Z,
            dpdu: 4.0 * Vec3::X,
            dpdv: 2.0 * Vec3::Y,
            footprint: 0.0,
        };
        let f = footprint(0.5, -Vec3::Z, Vec3::Z, &at, None);
        assert!((f - 0.5 / 8f32.sqrt()).abs() < 1e-6, "{f}");
        // At 60° from the normal the cone's section is twice as long.
        let dir = Vec3::new(3f32.sqrt() / 2.0, 0.0, -0.5) * 3.0;
        assert!((footprint(0.5, dir, Vec3::Z, &at, None) - 2.0 * f).abs() < 1e-6);
        // Scaled up twice by its transform, the plane holds four times the area per (u, v) unit.
        let t = Transform::scale(Vec3::splat(2.0)).unwrap();
        assert!((footprint(0.5, -Vec3::Z, Vec3::Z, &at, Some(&t)) - f / 2.0).abs() < 1e-6);
        // No derivatives: the finest level.
        let flat = TexPoint { dpdu: Vec3::ZERO, ..at };
        assert_eq!(footprint(0.5, -Vec3::Z, Vec3::Z, &flat, None), 0.0);
    }

    #[test]
    fn sphere_tex_point_follows_the_course_spherical_coordinates() {
        let c = Vec3::new(1.0, 2.0, 3.0);
        let at = |d: Vec3| sphere_tex_point(c + 2.0 * d, c, 2.0);
        // +x: φ = 0, θ = π/2; +z: φ = π/2; the top: θ = 0.
        assert!(at(Vec3::X).uv.abs_diff_eq(Vec2::new(0.5, 0.5), 1e-6));
        assert!(at(Vec3::Z).uv.abs_diff_eq(Vec2::new(0.25, 0.5), 1e-6));
        assert!((at(Vec3::Y).uv.y).abs() < 1e-6);
        assert!((at(-Vec3::Y).uv.y - 1.0).abs() < 1e-6);
        // The derivatives follow the point: a small step in u or v moves it by ∂p/∂u or ∂p/∂v times the step.
        let d = Vec3::new(0.3, 0.4, -0.5).normalize();
        let p = at(d);
        let h = 1e-3;
        let step = |du: f32, dv: f32| {
            let (u, v) = (p.uv.x + du, p.uv.y + dv);
            let (phi, theta) = (std::f32::consts::PI - 2.0 * std::f32::consts::PI * u, std::f32::consts::PI * v);
            c + 2.0 * Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin())
        };
        assert!(((step(h, 0.0) - step(-h, 0.0)) / (2.0 * h)).abs_diff_eq(p.dpdu, 1e-2), "{}", p.dpdu);
        assert!(((step(0.0, h) - step(0.0, -h)) / (2.0 * h)).abs_diff_eq(p.dpdv, 1e-2), "{}", p.dpdv);
        assert!(p.n.abs_diff_eq(d, 1e-6));
    }
}
