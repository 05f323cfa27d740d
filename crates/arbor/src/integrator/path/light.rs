//! The path tracer's light: next event estimation (a light sample and its shadow ray at a vertex) and
//! the weights that keep it and the light a bounce meets from counting twice, by the power heuristic
//! (Veach 1997, 9.2) under `MIS`, else all-or-nothing as the course asks. Costs: a light sample is one
//! shadow ray; the light choice is a walk over the lights that a ray can meet.

use super::PathTracer;
use crate::integrator::offset::shadow_ray;
use crate::integrator::roulette;
use crate::integrator::RayLog;
use crate::material::Brdf;
use crate::math::{Aabb, Color, Ray, Vec2, Vec3};
use crate::sampler::SampleStream;
use crate::scene::{Scene, SceneGeometry, Surface};

/// The world boxes of the scene's emitting objects, each grown by a little more than rounding, for
/// [`PathTracer::may_meet_light`]; `None` when a ray may meet light anywhere (an environment, or an
/// emitting plane).
pub(super) fn light_boxes(scene: &Scene) -> Option<Vec<Aabb>> {
    let emits = |object: u32| scene.object_emission.get(object as usize).is_some_and(|e| e.is_some());
    let g = &scene.geometry;
    if scene.environment.is_some() || g.planes.iter().any(|p| emits(p.object)) {
        return None;
    }
    let grown = |b: Aabb| {
        let pad = Vec3::splat(1e-4 * b.min.abs().max(b.max.abs()).max_element().max(1.0));
        Aabb::new(b.min - pad, b.max + pad)
    };
    Some(g.objects.objects.iter().filter(|o| emits(o.object)).map(|o| grown(o.bounds)).collect())
}

impl PathTracer<'_> {
    /// Whether a ray from `o` along `d` may meet an emitting object: false only when it misses every
    /// emitter's box. (A ray along a grown box's face, where a lane's slab test is NaN, lies outside
    /// the emitter itself.) Costs a slab test per emitter.
    pub(super) fn may_meet_light(&self, o: Vec3, d: Vec3) -> bool {
        let Some(boxes) = &self.light_boxes else { return true };
        let inv = d.recip();
        boxes.iter().any(|b| {
            let (t0, t1) = ((b.min - o) * inv, (b.max - o) * inv);
            let (near, far) = (t0.min(t1).max_element(), t0.max(t1).min_element());
            !(near > far || far < 0.0)
        })
    }

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::AccelConfig;
    use crate::renderer::PathOptions;
    use crate::sampler::Rng;
    use crate::scene::parse_desc;

    /// Every ray whose closest hit is an emitter passes [`PathTracer::may_meet_light`], and most others
    /// do not: a ceiling quad of zero thickness (its box flat in z), a scaled and moved sphere, and a
    /// wall between them that glows not.
    #[test]
    fn rays_that_meet_an_emitter_pass_the_light_boxes() {
        let text = r#"<Scene><Cameras><Camera id="1"><Position>0 0 5</Position><Gaze>0 0 -1</Gaze>
            <Up>0 1 0</Up><NearPlane>-1 1 -1 1</NearPlane><NearDistance>2</NearDistance>
            <ImageResolution>4 4</ImageResolution><ImageName>l.png</ImageName></Camera></Cameras>
            <Materials><Material id="1"><AmbientReflectance>0 0 0</AmbientReflectance><DiffuseReflectance>0.5 0.5 0.5</DiffuseReflectance>
            <SpecularReflectance>0 0 0</SpecularReflectance></Material></Materials>
            <Transformations><Scaling id="1">0.3 0.3 0.3</Scaling><Translation id="1">2 -1 0.5</Translation></Transformations>
            <VertexData>-1 -1 2  1 -1 2  1 1 2  -1 1 2  0 0 0  -3 -3 0  3 -3 0  3 3 0</VertexData>
            <Objects>
                <LightMesh id="1"><Material>1</Material><Radiance>5 5 5</Radiance><Faces>1 3 2 1 4 3</Faces></LightMesh>
                <LightSphere id="1"><Material>1</Material><Center>5</Center><Radius>1</Radius>
                    <Radiance>2 2 2</Radiance><Transformations>s1 t1</Transformations></LightSphere>
                <Mesh id="1"><Material>1</Material><Faces>6 7 8</Faces></Mesh>
            </Objects></Scene>"#;
        let scene =
            Scene::build(parse_desc(text, std::path::Path::new("l.xml")).unwrap(), &AccelConfig::default(), None)
                .unwrap();
        let tracer = PathTracer::new(&scene, PathOptions::default(), false);
        assert_eq!(tracer.light_boxes.as_ref().map(Vec::len), Some(2));
        let (mut met, mut passed_by) = (0, 0);
        let mut rng = Rng::for_sample(1, 2, 3, 4);
        for _ in 0..20_000 {
            let o = Vec3::new(rng.next_f32() * 8.0 - 4.0, rng.next_f32() * 8.0 - 4.0, rng.next_f32() * 4.0 - 1.0);
            let d = Vec3::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5, rng.next_f32() - 0.5);
            let ray = Ray::new(o, d);
            let emitter = scene.geometry.intersect(&ray, f32::INFINITY).is_some_and(|h| {
                let s = scene.surface(&ray, &h);
                scene.object_emission[s.object as usize].is_some()
            });
            let may = tracer.may_meet_light(o, d);
            assert!(may || !emitter, "a ray from {o} along {d} meets an emitter its box test missed");
            met += emitter as u32;
            passed_by += !may as u32;
        }
        assert!(met > 300 && passed_by > 5_000, "{met} rays met emitters, {passed_by} were turned away");
        // With an environment any ray may meet light.
        let mut with_env = scene;
        with_env.environment = Some(crate::light::environment::EnvMap::from_film_latlong(crate::film::Film {
            width: 2,
            height: 1,
            pixels: vec![Color::ONE; 2],
        }));
        assert!(light_boxes(&with_env).is_none());
    }
}
