//! Whitted-style recursive ray tracing as the METU and NYU courses define it: ambient plus Blinn-Phong
//! from every light that a shadow ray reaches, plus the specular lobes of mirrors, conductors and
//! dielectrics up to the recursion limit, with Beer's law along every segment travelled inside glass.
//! Glass seen from inside gets no ambient or Blinn-Phong terms, only its lobes.
//!
//! Every ray of a camera sample keeps its time (motion blur) and the pixel's ray cone, widened along
//! every segment travelled (for trilinear textures; [`crate::camera::RayCone`]). Rough materials send
//! their lobes' rays off the ideal directions ([`crate::material::perturb`]), one random choice per lobe.
//!
//! Secondary ray origins are pushed off the surface, by the scene's `ShadowRayEpsilon` or by the hit
//! point's floating-point error bound ([`super::offset::spawn_origin`] decides): to the side the new ray
//! leaves from, except in METU scenes, whose renderers never turn a surface's normal towards the ray:
//! there a surface shows the side of its stored normal from both sides, and its shadow and mirror rays
//! leave from that side (glass's lobes still leave on the side they go to).
//!
//! Emissive objects (CENG 795 hw6) are lights like the others, sampled once per light per shading point
//! with a shadow ray that stops short of the sampled point; and camera and specular rays that hit one
//! see its emission ([`Scene::emitted`]) on top of its own shading (black in the course's scenes). No
//! other ray reaches an emitter here, so nothing is counted twice.
//!
//! It reads the runtime scene only: materials ask their [`crate::material::SpecularLayer`] for lobes,
//! lights their [`crate::light::Light::sample`], never the description.

use super::offset::{shadow_ray, spawn_origin};
use super::prune::{Pruning, Shares, TreePlan, TREE_BUDGET};
use super::RayLog;
use crate::accel::Hit;
use crate::camera::{Camera, RayCone};
use crate::material::{beer, perturb, Material};
use crate::math::{Color, Ray, Vec2};
use crate::sampler::Rng;
use crate::scene::Scene;

/// The integrator for one render.
pub struct Whitted<'a> {
    scene: &'a Scene,
    cull_backfaces: bool,
    camera: Option<&'a Camera>,
    /// The camera's pixel cone (zero without a camera: the finest texture level).
    cone: RayCone,
    /// How trees too large for the budget are cut ([`super::prune`]); `None` for trees within it.
    pruning: Option<Pruning>,
}

/// What a ray carries down the recursion.
#[derive(Clone, Copy)]
struct Carried {
    /// Specular bounces so far.
    depth: u32,
    /// The absorption of the glass the ray travels in, if any.
    inside: Option<Color>,
    /// The pixel's cone, as wide as it is where the ray starts.
    cone: RayCone,
    /// The product of the lobe weights above the ray, largest channel (for pruning).
    weight: f32,
    /// The rays the ray's tree may trace, itself included ([`super::prune`]; infinite without a budget).
    allowance: f32,
}

impl<'a> Whitted<'a> {
    /// An integrator over `scene`; `cull_backfaces` applies to camera rays only.
    pub fn new(scene: &'a Scene, cull_backfaces: bool) -> Self {
        let pruning = TreePlan::of(scene).pruning;
        Whitted { scene, cull_backfaces, camera: None, cone: RayCone::default(), pruning }
    }

    /// The same integrator tracing every tree whole, pruned or not, whatever it costs: the exact answer
    /// that pruning is checked against.
    pub fn exact(self) -> Self {
        Whitted { pruning: None, ..self }
    }

    /// The integrator for the camera rays of `camera`, which a background texture spans.
    pub fn with_camera(self, camera: &'a Camera) -> Self {
        Whitted { camera: Some(camera), cone: camera.pixel_cone(), ..self }
    }

    /// Radiance (in the scene's units) along a camera ray.
    pub fn li_camera(&self, ray: &Ray, rng: &mut Rng, log: &mut RayLog) -> Color {
        let ray = self.camera_ray(ray);
        let hit = log.intersect(&self.scene.geometry, &ray, f32::INFINITY);
        self.li_camera_hit(&ray, hit, rng, log)
    }

    /// The camera ray as it is traced: culling back faces if the render asks for it.
    pub fn camera_ray(&self, ray: &Ray) -> Ray {
        ray.with_culling(self.cull_backfaces)
    }

    /// [`Whitted::li_camera`] for a camera ray already traced (with others, by
    /// [`crate::scene::SceneGeometry::intersect_many`]): `ray` is [`Whitted::camera_ray`]'s and `hit` its
    /// closest hit.
    pub fn li_camera_hit(&self, ray: &Ray, hit: Option<Hit>, rng: &mut Rng, log: &mut RayLog) -> Color {
        log.rays += 1;
        if self.pruning.is_none() {
            return self.shade(ray, hit, self.camera_carried(f32::INFINITY), rng, log);
        }
        // The whole (pruned) tree while it stays within the budget; a tree that needs more is traced
        // again from the same random numbers, with the budget shared out by weight.
        let start = rng.clone();
        (log.tree, log.capped) = (1, false);
        let c = self.shade(ray, hit, self.camera_carried(f32::INFINITY), rng, log);
        if !log.capped {
            return c;
        }
        *rng = start;
        (log.tree, log.capped) = (1, false);
        let c = self.shade(ray, hit, self.camera_carried(TREE_BUDGET as f32), rng, log);
        log.capped_samples += u64::from(log.capped);
        c
    }

    fn camera_carried(&self, allowance: f32) -> Carried {
        Carried { depth: 0, inside: None, cone: self.cone, weight: 1.0, allowance }
    }

    /// The allowance of the ray of a lobe of weight `w` from a hit at `depth` whose own weight is
    /// `weight`, or `None` when it is not traced: pruned (it cannot change the image), or given less
    /// than one ray of the budget `shares` hands out.
    #[inline]
    fn allowance(&self, weight: f32, w: f32, depth: u32, shares: &mut Shares, log: &mut RayLog) -> Option<f32> {
        let Some(p) = &self.pruning else { return Some(f32::INFINITY) };
        if p.prunes(weight * w, self.scene.max_depth - depth - 1) {
            shares.skip(w);
            return None;
        }
        if shares.unlimited() {
            // The first pass: the whole tree, until it is found to need more than the budget.
            log.capped |= log.tree >= TREE_BUDGET;
            return (!log.capped).then_some(f32::INFINITY);
        }
        let share = shares.take(w);
        log.capped |= share.is_none();
        share
    }

    /// Radiance along `ray`.
    fn li(&self, ray: &Ray, carried: Carried, rng: &mut Rng, log: &mut RayLog) -> Color {
        log.rays += 1;
        log.tree += 1;
        let hit = log.intersect(&self.scene.geometry, ray, f32::INFINITY);
        self.shade(ray, hit, carried, rng, log)
    }

    /// Radiance along `ray` given its closest hit.
    fn shade(&self, ray: &Ray, hit: Option<Hit>, carried: Carried, rng: &mut Rng, log: &mut RayLog) -> Color {
        let Carried { depth, inside, cone, weight, allowance } = carried;
        let scene = self.scene;
        let Some(hit) = hit else {
            return self.miss(ray, depth);
        };
        let mut s = scene.surface(ray, &hit);
        let m = scene.material(&s);
        // Textures replace the Blinn-Phong terms and the shading normal; the specular layer stays.
        let textured = scene.textured(ray, &hit, &mut s, cone);
        if let Some(c) = textured.and_then(|t| t.replace_all) {
            return c;
        }
        let own;
        let terms = match textured {
            Some(t) => {
                own = Material { ambient: t.ambient, diffuse: t.diffuse, specular: t.specular, layer: None, ..*m };
                &own
            }
            None => m,
        };
        let d = ray.dir;
        let front = d.dot(s.ng) < 0.0;
        // The side the surface shows: the one the ray arrives on, or (the METU renderers) always its
        // stored normal's, so a back face is lit by the lights in front of it (windmill_smooth's and
        // grass_desert's unculled references).
        let (ng, ns) = if front || !scene.flip_back_faces { (s.ng, s.ns) } else { (-s.ng, -s.ns) };

        // A refractive surface hit from inside only refracts and reflects: its ambient and Blinn-Phong
        // terms belong to its outside (the official renderers agree: scienceTree_glass.png).
        let local = front || !m.transmits();
        let mut color = if local { terms.ambient * scene.ambient } else { Color::ZERO };
        color += scene.emitted(&s, -d);
        // Light is measured at the surface point itself; only the shadow ray starts off the surface.
        let shadow_origin = spawn_origin(scene.offset, &s, ng);
        let wo = if m.brdf.is_some() { -d.normalize() } else { -d };
        for light in scene.lights.iter().filter(|_| local) {
            let Some(ls) = light.sample(s.p, ns, rng.next_2d()) else { continue };
            if ns.dot(ls.wi) <= 0.0 {
                continue;
            }
            log.rays += scene.shadows as u64;
            let on_surface = light.object().is_some();
            let (shadow, t_max) = shadow_ray(scene.offset, shadow_origin, s.p, &ls, on_surface);
            let shadow = shadow.with_time(ray.time);
            if scene.shadows && log.occluded(&scene.geometry, &shadow, t_max) {
                continue;
            }
            color += terms.eval_cos(ns, ls.wi, wo) * ls.irradiance;
        }

        if depth < scene.max_depth && m.layer.is_some() {
            // Lobes see the shading normal unless it disagrees with the geometric one about which side
            // the ray comes from (possible at silhouettes of smooth meshes).
            let n = if (d.dot(s.ns) < 0.0) == front { s.ns } else { s.ng };
            let lobes = m.specular_lobes(d, n);
            let mut shares = Shares::new(allowance, &lobes);
            for lobe in lobes {
                if lobe.weight == Color::ZERO {
                    continue;
                }
                let w = lobe.weight.max_element();
                let Some(allowance) = self.allowance(weight, w, depth, &mut shares, log) else { continue };
                let dir = if m.roughness > 0.0 { perturb(lobe.dir, m.roughness, rng.next_2d()) } else { lobe.dir };
                // Glass's lobes leave on the side they go to (into or out of it). A mirror's leave on
                // the side the surface shows, like its shadow rays: the METU renderers offset them
                // along the stored normal even when they head the other way (spheres_mirror,
                // grass_desert); with normals turned to the ray, that is the lobe's own side.
                let side = if m.transmits() || scene.flip_back_faces { dir } else { ng };
                let origin = spawn_origin(scene.offset, &s, side);
                let next_inside = m.medium_after(&lobe, front, inside);
                let next = Carried {
                    depth: depth + 1,
                    inside: next_inside,
                    cone: cone.after(hit.t * d.length()),
                    weight: weight * w,
                    allowance,
                };
                let before = log.tree;
                let l = self.li(&Ray::new(origin, dir).with_time(ray.time), next, rng, log);
                shares.spent(log.tree - before);
                color += lobe.weight * l;
            }
        }
        match inside {
            Some(absorption) => color * beer(absorption, hit.t * ray.dir.length()),
            None => color,
        }
    }

    /// What a ray that hits nothing sees: the environment map, else the background colour for camera
    /// rays and black for the others.
    fn miss(&self, ray: &Ray, depth: u32) -> Color {
        let scene = self.scene;
        if let Some(env) = &scene.environment {
            return env.eval(ray.dir) / scene.radiance_scale;
        }
        if depth == 0 {
            if let (Some(t), Some(cam)) = (scene.background_texture, self.camera) {
                // The texture covers the image plane, pixel (i, j) at (i / width, j / height): an image
                // of the film's size shows one texel per pixel.
                if let Some(px) = cam.project(ray.origin + ray.dir) {
                    let (i, j) = (px.x.floor() / cam.width as f64, px.y.floor() / cam.height as f64);
                    let uv = Vec2::new(i as f32, j as f32);
                    return scene.textures[t].eval_uv(uv) / scene.radiance_scale;
                }
            }
            scene.background
        } else {
            Color::ZERO
        }
    }
}
