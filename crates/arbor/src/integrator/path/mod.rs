//! A unidirectional path tracer (Kajiya 1986) as the course defines it (CENG 795 hw6), with pbrt's
//! structure (Pharr, Jakob & Humphreys, *Physically Based Rendering*, 4th ed., 13.3-13.4): one path per
//! camera sample, one bounce direction per vertex, the throughput `beta` carried along.
//!
//! - Bounces: uniform over the hemisphere of the shading normal (pdf `1/2π`), or by the cosine with
//!   `ImportanceSampling` (pdf `cos θ/π`). Mirrors, conductors and dielectrics follow one of their
//!   lobes, picked in proportion to its weight, as delta directions; a METU camera follows every lobe of
//!   a refractive surface instead, as the course's renderer does ([`super::split`]). A material with both (a mirror
//!   with a diffuse colour, the course's usual kind) is a mixture: the bounce follows its BRDF or its
//!   lobes, chosen in proportion to the two parts' weights (the BRDF's `k_d + k_s` against the lobes'),
//!   and light sampling serves its BRDF part.
//! - Light: an emitter (or the environment) met by a ray counts, unless next event estimation sampled it
//!   already (the course: "discard its contribution"). With `NextEventEstimation`, every vertex of a
//!   surface with a BRDF part is lit by each light no ray can meet (point, spot, directional, the square
//!   area light) and by one of the others, chosen in proportion to its power, each with a shadow ray; with
//!   `MIS` the emitters met and sampled both count, weighted by the power heuristic (Veach 1997); the last
//!   vertex's bounce is then traced too, for the light it meets only. Without
//!   it, as in the course's plain references, lights no ray can meet give nothing (their radiance matches
//!   Arbor's within 1% that way). After a delta lobe, met light always counts in full.
//! - Length: at most `MaxRecursionDepth` bounces, or at random by one of the two Russian roulettes
//!   ([`super::roulette`]): the course's, biased, which a METU camera's `RussianRoulette` gets, and
//!   Arbor's unbiased one (`--roulette unbiased`, `--path-options roulette`).
//!
//! Materials without a BRDF are shaded as the normalized modified Blinn-Phong model (`k_d/π` plus a
//! lobe that conserves energy): the course's default Blinn-Phong terms are not a physical BRDF (their
//! diffuse part reflects π times the light it gets). There is no ambient term. Invariants: every
//! estimate but the course's roulette is unbiased for the options given (the furnace and convergence
//! tests check it; the course's roulette's test checks its `Σ (2 - q_k) E_k`); a sample's value depends
//! only on its random stream.
//!
//! Layout: `vertex` takes one hit and does the rest of a step (emission, light samples through
//! [`light`], the roulettes, the next direction or the split's branches), with what the path carries
//! between steps in a `PathState`. Two drivers call it: the render's [`PathTracer::li_camera_batch`]
//! steps a batch's paths together and traces their rays in batches ([`wavefront`]), and
//! [`PathTracer::li_camera_hit`] one path alone, each ray as it comes (a live view's ray inspector,
//! which records every query in order); both give a sample the same radiance, bit for bit.

mod light;
mod state;
mod wavefront;

use super::hemisphere::{cosine_hemisphere, uniform_hemisphere};
use super::offset::spawn_origin;
use super::roulette::{self, MAX_BOUNCES};
use super::split::{Branch, Branches};
use super::RayLog;
use crate::accel::Hit;
use crate::camera::Camera;
use crate::material::{beer, Brdf, BrdfModel, Material};
use crate::math::{Aabb, Color, Ray, Vec3};
use crate::renderer::{PathOptions, Roulette};
use crate::sampler::SampleStream;
use crate::scene::Scene;
use light::{Now, Shadows, Vertex};
use state::PathState;

/// The path tracer for one render.
pub struct PathTracer<'a> {
    scene: &'a Scene,
    options: PathOptions,
    cull_backfaces: bool,
    camera: Option<&'a Camera>,
    /// Probability of choosing each light a ray can meet for a light sample: its share of their total
    /// power; 0 for the others, which are all sampled at every vertex.
    pick: Vec<f32>,
    /// The lights of probability 0 in `pick`, in scene order: sampled at every vertex; each with
    /// whether its sample reads its random numbers (not a delta light).
    always: Vec<(usize, bool)>,
    /// The last light `pick` can choose: it takes what rounding leaves of `u`.
    last_pick: Option<usize>,
    /// Whether `pick` has a choice to make (two lights or more): only then is the number that makes it
    /// a padded dimension.
    several: bool,
    /// Whether each light is emissive geometry ([`crate::light::Light::object`]): its shadow rays stop
    /// short of the surface sampled.
    on_surface: Vec<bool>,
    /// The BRDF of each material as the path tracer shades it ([`path_brdf`]).
    brdfs: Vec<Brdf>,
    /// The emitting objects' boxes ([`light::light_boxes`]): the last vertex's bounce, which only
    /// looks for light, is not traced when it misses them all.
    light_boxes: Option<Vec<Aabb>>,
}

impl<'a> PathTracer<'a> {
    /// A path tracer over `scene`; `cull_backfaces` applies to camera rays only.
    pub fn new(scene: &'a Scene, options: PathOptions, cull_backfaces: bool) -> Self {
        let met = |i: usize| scene.lights[i].object().is_some() || scene.environment_light == Some(i);
        let powers: Vec<f32> =
            (0..scene.lights.len()).map(|i| if met(i) { scene.lights[i].power().max(0.0) } else { 0.0 }).collect();
        let total: f32 = powers.iter().sum();
        let pick: Vec<f32> = if total > 0.0 && total.is_finite() {
            powers.iter().map(|p| p / total).collect()
        } else {
            let n = (0..scene.lights.len()).filter(|&i| met(i)).count().max(1) as f32;
            (0..scene.lights.len()).map(|i| if met(i) { 1.0 / n } else { 0.0 }).collect()
        };
        let always = (0..pick.len()).filter(|&i| pick[i] == 0.0).map(|i| (i, !scene.lights[i].is_delta())).collect();
        let last_pick = pick.iter().rposition(|&p| p > 0.0);
        let several = pick.iter().filter(|&&p| p > 0.0).count() > 1;
        let on_surface = scene.lights.iter().map(|l| l.object().is_some()).collect();
        let brdfs = scene.materials.iter().map(path_brdf).collect();
        let light_boxes = light::light_boxes(scene);
        PathTracer {
            scene,
            options,
            cull_backfaces,
            camera: None,
            pick,
            always,
            last_pick,
            several,
            on_surface,
            brdfs,
            light_boxes,
        }
    }

    /// The path tracer for the camera rays of `camera`.
    pub fn with_camera(self, camera: &'a Camera) -> Self {
        PathTracer { camera: Some(camera), ..self }
    }

    /// The camera ray as it is traced: culling back faces if the render asks for it.
    pub fn camera_ray(&self, ray: &Ray) -> Ray {
        ray.with_culling(self.cull_backfaces)
    }

    /// Radiance (in the scene's units) along the camera ray `ray`, whose closest hit is `hit`.
    pub fn li_camera_hit(&self, ray: &Ray, hit: Option<Hit>, sample: &mut SampleStream, log: &mut RayLog) -> Color {
        log.rays += 1;
        let mut l = Color::ZERO;
        let (mut ray, mut hit) = (*ray, hit);
        let mut p = PathState::camera();
        // Paths split at refractive surfaces ([`super::split`]) leave branches here.
        let mut branches = Branches::default();
        loop {
            while let Some((origin, dir)) = self.vertex(&ray, hit, &mut p, &mut l, &mut branches, sample, log, &mut Now)
            {
                ray = Ray::new(origin, dir).with_time(ray.time);
                log.rays += 1;
                hit = log.intersect(&self.scene.geometry, &ray, f32::INFINITY);
            }
            let Some(b) = self.next_branch(&mut branches, sample) else { break };
            ray = b.ray;
            p = PathState::branch(&b, p.e);
            log.rays += 1;
            hit = log.intersect(&self.scene.geometry, &ray, f32::INFINITY);
        }
        l
    }

    /// One vertex of the path `p`, where its ray `ray` met `hit` (or nothing): adds the light it gathers
    /// there to `l`, leaves the other lobes of a split in `branches`, advances `p` and returns the origin
    /// and direction of the ray it goes on with, untraced; `None` when the path (or this branch) ends.
    /// The ray is built and traced by the caller: returned whole, it went through memory. Shadow rays
    /// go to `shadows`, which traces them at once or with the step's others.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn vertex(
        &self,
        ray: &Ray,
        hit: Option<Hit>,
        p: &mut PathState,
        l: &mut Color,
        branches: &mut Branches,
        sample: &mut SampleStream,
        log: &mut RayLog,
        shadows: &mut impl Shadows,
    ) -> Option<(Vec3, Vec3)> {
        let scene = self.scene;
        let o = self.options;
        let max_bounces = if o.roulette == Roulette::Off { scene.max_depth } else { MAX_BOUNCES };
        let course = o.roulette == Roulette::Course;
        let Some(h) = hit else {
            let w = p.last.map_or(1.0, |(from, pdf)| {
                self.met_light_weight(scene.environment_light, from, ray.dir.normalize(), pdf)
            });
            *l += p.beta * self.miss(ray, p.bounce) * w;
            return None;
        };
        if let Some(absorption) = p.inside {
            p.beta *= beer(absorption, h.t * ray.dir.length());
        }
        let mut s = scene.surface(ray, &h);
        let m = scene.material(&s);
        // The vertex's own light goes to `l`, or under the course's roulette to `p.e` first, which the
        // roulette then weighs.
        let own = if course { &mut p.e } else { &mut *l };
        let emitted = scene.emitted(&s, -ray.dir);
        if emitted != Color::ZERO {
            let w = p.last.map_or(1.0, |(from, pdf)| {
                self.met_light_weight(scene.light_of(s.object), from, ray.dir.normalize(), pdf)
            });
            *own += p.beta * emitted * w;
        }
        // Past the last vertex (reached by its bounce under MIS) a path only meets light.
        if p.bounce > max_bounces {
            if course {
                shadows.course(p.t, &mut p.e, l, sample);
            }
            return None;
        }
        // Only textured objects ask for their textures: the common case builds no shading terms.
        let textured =
            if scene.has_textures(s.object) { scene.textured(ray, &h, &mut s, Default::default()) } else { None };
        if let Some(c) = textured.and_then(|t| t.replace_all) {
            *own += p.beta * c;
            if course {
                shadows.course(p.t, &mut p.e, l, sample);
            }
            return None;
        }
        // One by one: picked as a pair, the two colours went through memory in pieces of other
        // sizes than they are read in, and the reads waited for the writes.
        let kd = textured.as_ref().map_or(m.diffuse, |t| t.diffuse);
        let ks = textured.as_ref().map_or(m.specular, |t| t.specular);
        let d = ray.dir.normalize();
        let front = d.dot(s.ng) < 0.0;
        // Shade the side the ray arrives on.
        let (ng, ns) = if front { (s.ng, s.ns) } else { (-s.ng, -s.ns) };
        let brdf = &self.brdfs[s.material];
        let local = front || !m.transmits();
        // A material may have both a BRDF and a specular layer (a mirror with a diffuse colour): the
        // bounce follows the BRDF with probability `p_brdf`, in proportion to the two parts' weights,
        // and the layer's lobes otherwise; light sampling serves the BRDF part wherever it is.
        let has_brdf = local && (kd != Color::ZERO || ks != Color::ZERO);
        let lobes = if m.layer.is_some() {
            let n = if (d.dot(s.ns) < 0.0) == front { s.ns } else { s.ng };
            m.specular_lobes(d, n)
        } else {
            Vec::new()
        };
        let lobe_total: f32 = lobes.iter().map(|lb| luminance(lb.weight)).sum();
        // The course's renderer follows every lobe of a refractive surface and its BRDF bounce too.
        let split = o.split_refraction
            && m.transmits()
            && p.bounce < scene.max_depth.min(max_bounces)
            && branches.room_for(&lobes);
        let p_brdf = match (m.layer.is_some(), has_brdf) {
            _ if split => 1.0,
            (false, _) => 1.0,
            (true, false) => 0.0,
            (true, true) => {
                let b = luminance(kd) + luminance(ks);
                if b + lobe_total > 0.0 {
                    b / (b + lobe_total)
                } else {
                    0.0
                }
            }
        };
        let at = Vertex { s: &s, ns, wo: -d, kd, ks, brdf, f: brdf.constant(kd, ks), p_brdf, time: ray.time };

        // Light sampling, where a BRDF can take it (not at a delta surface's lobes).
        if has_brdf {
            let origin = spawn_origin(scene.offset, &s, ng);
            // With one light or none the choice is fixed: a plain number, no padded dimension spent.
            let pick = if self.several { sample.padded_1d() } else { sample.rng.next_f32() };
            let u = sample.padded_2d();
            if o.next_event {
                for &(i, sampled) in &self.always {
                    // A delta light's numbers are never read: plain ones, not a padded dimension
                    // (the independent sampler draws the same numbers either way).
                    let u = if sampled { sample.padded_2d() } else { sample.rng.next_2d() };
                    self.direct(&at, p.beta, origin, i, u, 1.0, log, own, shadows);
                }
                if let Some((i, chosen)) = self.choose_light(pick) {
                    self.direct(&at, p.beta, origin, i, u, chosen, log, own, shadows);
                }
            }
        }
        if course {
            let q = shadows.course(p.t, &mut p.e, l, sample)?;
            p.beta /= q;
        }

        // The last vertex's bounce is traced under MIS only, and only for the light it meets (the vertex
        // past the last, above): its light samples are weighed against it, so without it their light would
        // go missing (9% of `veach-ajar`'s at MaxRecursionDepth 1), and counted in full instead they bring
        // back the light samples' fireflies near lights. Its lobes stay untraced, as without MIS.
        let last = p.bounce >= max_bounces;
        if last && !o.mis {
            return None;
        }
        // The next direction: a delta lobe of the specular layer, or a bounce over the hemisphere.
        // With a layer, one number picks the part and, rescaled, the lobe.
        let part = if m.layer.is_some() && !split { sample.rng.next_f32() } else { 0.0 };
        if split {
            branches.push(&lobes, |lobe| Branch {
                ray: Ray::new(spawn_origin(scene.offset, &s, lobe.dir), lobe.dir).with_time(ray.time),
                beta: p.beta * lobe.weight,
                t: if course { p.t * lobe.weight } else { p.t },
                inside: m.medium_after(lobe, front, p.inside),
                bounce: p.bounce + 1,
            });
            if !has_brdf {
                return None;
            }
        }
        let next = if part >= p_brdf {
            let total = lobe_total;
            if total <= 0.0 || last {
                return None;
            }
            let mut pick = (part - p_brdf) / (1.0 - p_brdf) * total;
            let lobe = lobes.iter().find(|lb| {
                pick -= luminance(lb.weight);
                pick < 0.0
            })?;
            p.beta *= lobe.weight * (total / luminance(lobe.weight));
            if course {
                p.t *= lobe.weight;
            }
            if p_brdf > 0.0 {
                p.beta /= 1.0 - p_brdf;
            }
            p.last = None;
            p.inside = m.medium_after(lobe, front, p.inside);
            lobe.dir
        } else {
            let (wi, pdf) = if o.importance_sampling {
                cosine_hemisphere(ns, sample.padded_2d())
            } else {
                uniform_hemisphere(ns, sample.padded_2d())
            };
            let cos = ns.dot(wi);
            if pdf <= 0.0 || cos <= 0.0 || wi.dot(ng) <= 0.0 {
                return None;
            }
            let f = at.f(wi);
            p.beta *= f * (cos / pdf);
            if course {
                p.t *= f;
            }
            if p_brdf < 1.0 {
                p.beta /= p_brdf;
            }
            p.last = Some((s.p, p_brdf * pdf));
            wi
        };
        if o.roulette == Roulette::Unbiased {
            let q = roulette::unbiased(p.beta, sample)?;
            p.beta /= q;
        }
        if p.beta == Color::ZERO {
            return None;
        }
        p.bounce += 1;
        let origin = spawn_origin(scene.offset, &s, next);
        if last && !self.may_meet_light(origin, next) {
            return None;
        }
        Some((origin, next))
    }

    /// The next branch of a split path to trace, after Arbor's unbiased roulette (the roulette a bounce
    /// gets before its ray is traced) where the camera has it.
    fn next_branch(&self, branches: &mut Branches, sample: &mut SampleStream) -> Option<Branch> {
        while let Some(mut b) = branches.pop() {
            if self.options.roulette == Roulette::Unbiased {
                let Some(q) = roulette::unbiased(b.beta, sample) else { continue };
                b.beta /= q;
            }
            return Some(b);
        }
        None
    }

    /// What a ray that hits nothing brings back: the environment, else the background for camera rays.
    fn miss(&self, ray: &Ray, bounce: u32) -> Color {
        let scene = self.scene;
        match &scene.environment {
            Some(env) => env.eval(ray.dir) / scene.radiance_scale,
            None if bounce == 0 && self.camera.is_some() => scene.background,
            None => Color::ZERO,
        }
    }
}

/// The BRDF the path tracer gives a material: its own, or the normalized modified Blinn-Phong model
/// with its Phong exponent.
fn path_brdf(m: &Material) -> Brdf {
    m.brdf.unwrap_or(Brdf { model: BrdfModel::ModifiedBlinnPhong { normalized: true }, exponent: m.phong_exponent })
}

fn luminance(c: Color) -> f32 {
    crate::tonemap::luminance(c).max(0.0)
}
