//! The path tracer's light: next event estimation (a light sample and its shadow ray at a vertex) and
//! the weights that keep it and the light a bounce meets from counting twice, by the power heuristic
//! (Veach 1997, 9.2) under `MIS`, else all-or-nothing as the course asks. Costs: a light sample is one
//! shadow ray; the light choice is a walk over the lights that a ray can meet.

use super::PathTracer;
use crate::integrator::offset::shadow_ray;
use crate::integrator::roulette;
use crate::integrator::RayLog;
use crate::material::Brdf;
use crate::math::{Color, Ray, Vec2, Vec3};
use crate::sampler::SampleStream;
use crate::scene::{SceneGeometry, Surface};

impl PathTracer<'_> {
    /// A light chosen in proportion to its power by `u` in [0, 1), and the probability of that choice.
    #[inline]
    pub(super) fn choose_light(&self, u: f32) -> Option<(usize, f32)> {
        let mut rest = u;
        let last = self.last_pick?;
        for (i, &p) in self.pick.iter().enumerate() {
            if rest < p || i == last {
                return Some((i, p));
            }
            rest -= p;
        }
        None
    }

    /// The weight of light met by a bounce whose direction had density `bsdf_pdf`, when light `light`
    /// could also have been sampled towards it from `from`: 1 without next event estimation, 0 with it,
    /// the power heuristic with MIS.
    pub(super) fn met_light_weight(&self, light: Option<usize>, from: Vec3, dir: Vec3, bsdf_pdf: f32) -> f32 {
        let o = self.options;
        match light {
            _ if !o.next_event => 1.0,
            Some(i) if o.mis => {
                let light_pdf = self.pick[i] * self.scene.lights[i].pdf(from, dir);
                power_heuristic(bsdf_pdf, light_pdf)
            }
            Some(_) => 0.0,
            // Light no sample could choose (an environment given on the command line only).
            None => 1.0,
        }
    }

    /// Adds to `l` the light `i` brings to the vertex `at` of throughput `beta` through one sample `u` of
    /// it, a shadow ray from `origin` (traced by `shadows`), when it was chosen with probability
    /// `chosen`; nothing when the sample is below the surface or blocked. Added rather than returned:
    /// an `Option<Color>` comes back through memory, and the caller's wider load of it stalled on the
    /// narrower stores.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub(super) fn direct(
        &self,
        at: &Vertex,
        beta: Color,
        origin: Vec3,
        i: usize,
        u: Vec2,
        chosen: f32,
        log: &mut RayLog,
        l: &mut Color,
        shadows: &mut impl Shadows,
    ) {
        let scene = self.scene;
        let (s, ns) = (at.s, at.ns);
        let light = &scene.lights[i];
        let Some(ls) = light.sample(s.p, ns, u).filter(|ls| ns.dot(ls.wi) > 0.0) else { return };
        log.rays += 1;
        let (shadow, t_max) = shadow_ray(scene.offset, origin, s.p, &ls, self.on_surface[i]);
        // The light is worked out before the shadow ray is traced: the wavefront traces it later, with
        // the step's others, when this vertex's surface is gone.
        let w = if self.options.mis && ls.pdf > 0.0 {
            power_heuristic(chosen * ls.pdf, at.p_brdf * self.bounce_pdf(ns, ls.wi))
        } else {
            1.0
        };
        let f = at.f(ls.wi) * ns.dot(ls.wi);
        shadows.cast(
            &scene.geometry,
            log,
            &shadow.with_time(at.time),
            t_max,
            beta * f * ls.irradiance * (w / chosen),
            l,
        );
    }

    /// The density of a bounce direction `wi` about the shading normal `n`.
    fn bounce_pdf(&self, n: Vec3, wi: Vec3) -> f32 {
        let cos = n.dot(wi);
        match () {
            _ if cos <= 0.0 => 0.0,
            _ if self.options.importance_sampling => cos / std::f32::consts::PI,
            _ => 1.0 / (2.0 * std::f32::consts::PI),
        }
    }
}

/// Where a vertex's shadow rays are traced: at once ([`Now`]), or with the other paths' of a step
/// (the wavefront). Either way a vertex's light is summed in the order the one-path loop sums it.
pub(super) trait Shadows {
    /// Light `c` that reaches a vertex unless something lies on `ray` in `(0, t_max)`: added to `own`
    /// (the path's light, or under the course's roulette the vertex's) once the ray is traced.
    fn cast(&mut self, g: &SceneGeometry, log: &mut RayLog, ray: &Ray, t_max: f32, c: Color, own: &mut Color);

    /// The course's roulette at a vertex of BRDF product `t` ([`roulette::course`]), whose own light
    /// `e` may still be waiting on its shadow rays: `q` when the path goes on.
    fn course(&mut self, t: Color, e: &mut Color, l: &mut Color, sample: &mut SampleStream) -> Option<f32>;
}

/// Shadow rays traced when they are cast: one path at a time.
pub(super) struct Now;

impl Shadows for Now {
    #[inline(always)]
    fn cast(&mut self, g: &SceneGeometry, log: &mut RayLog, ray: &Ray, t_max: f32, c: Color, own: &mut Color) {
        if !log.occluded(g, ray, t_max) {
            *own += c;
        }
    }

    #[inline(always)]
    fn course(&mut self, t: Color, e: &mut Color, l: &mut Color, sample: &mut SampleStream) -> Option<f32> {
        let q = roulette::course(t, *e, l, sample);
        *e = Color::ZERO;
        q
    }
}

/// What light sampling and the bounce need of a path vertex.
pub(super) struct Vertex<'s> {
    pub(super) s: &'s Surface,
    /// The shading normal on the side the ray arrived on.
    pub(super) ns: Vec3,
    pub(super) wo: Vec3,
    pub(super) kd: Color,
    pub(super) ks: Color,
    pub(super) brdf: &'s Brdf,
    /// The BRDF's value when it does not depend on the directions ([`Brdf::constant`]).
    pub(super) f: Option<Color>,
    /// The probability that the vertex's bounce samples its BRDF, against which MIS weighs its light
    /// samples.
    pub(super) p_brdf: f32,
    pub(super) time: f32,
}

impl Vertex<'_> {
    /// The BRDF towards `wi`, which must be above the shading normal (`ns · wi > 0`).
    #[inline]
    pub(super) fn f(&self, wi: Vec3) -> Color {
        match self.f {
            Some(c) => c,
            None => self.brdf.f(self.kd, self.ks, wi, self.wo, self.ns),
        }
    }
}

/// Veach's power heuristic (β = 2) for a sample of density `a` against another technique's `b`.
fn power_heuristic(a: f32, b: f32) -> f32 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 && (a2 + b2).is_finite() {
        a2 / (a2 + b2)
    } else if a.is_infinite() {
        1.0
    } else {
        0.0
    }
}
