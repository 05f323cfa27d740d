//! The path tracer's two Russian roulettes ([`Roulette`]), which end paths at random instead of at
//! `MaxRecursionDepth`.
//!
//! - [`course`]: the course's roulette (CENG 795 hw6), what a METU camera's `RussianRoulette` gets
//!   because it is what the course's official images show (read off their pixels: docs/reference-results.md).
//!   At path vertex k (the camera's hit is 0) the path survives with probability `q_k = min(1, max(t_k))`,
//!   `t_k` the product of the BRDF values (a delta lobe: its weight) of the vertices before it, without
//!   cosines, densities or earlier `1/q`. The vertex's own light `E_k` (emission met, light samples) is
//!   kept as it is when the path ends there, and divided by `q_k` with the rest of the path when it goes
//!   on. Its expectation is `Σ (2 - q_k) E_k` where the light is `Σ E_k`: biased, brighter; it is the
//!   assignment's `(F - (1-q) C) / q` with `C = E_k` but without subtracting `(1-q) C`. Its variance is
//!   infinite: surviving k diffuse vertices divides a path by about `π^(k(k+1)/2)`.
//! - [`unbiased`]: Arbor's, after each bounce: the path survives with probability `q = min(1, max(beta))`
//!   of its throughput `beta` and is divided by `q` (pbrt's form): unbiased.
//!
//! Neither has a depth limit but [`MAX_BOUNCES`], a bound on a render's time. Cost: one random number
//! per vertex where `q < 1`.

use crate::math::Color;
use crate::sampler::SampleStream;

#[cfg(doc)]
use crate::renderer::Roulette;

/// The longest path either Russian roulette may build: a bound on a render's time, as the course's
/// roulette has infinite variance and a glossy lobe or a delta one can keep a survival probability at 1.
/// Far beyond any visible light: past it, a path would on average gather at most twice (the course's
/// `2 - q`) what an unbiased one does, which falls by the albedo at each bounce (`0.9^256 < 2e-12`); and
/// under the course's roulette a path of diffuse bounces (BRDF at most `1/π`) survives vertices 1 to k
/// with probability at most `π^(-k(k+1)/2)`, 4e-11 for k = 6.
pub const MAX_BOUNCES: u32 = 256;

/// The course's roulette at a path vertex whose BRDF values so far multiply to `t` and whose own light
/// (emission and light samples, times the path's throughput) is `e`: adds to `l` what the vertex keeps,
/// `e` when the path ends here and `e / q` when it goes on, and returns `q`, by which the rest of the path
/// is divided, or `None`. A certain survival (`q = 1`, the camera's first hit) draws no number.
#[inline]
pub fn course(t: Color, e: Color, l: &mut Color, sample: &mut SampleStream) -> Option<f32> {
    let (q, survives) = course_draw(t, sample);
    course_keep(e, q, survives, l);
    survives.then_some(q)
}

/// The course's roulette's choice at a vertex of BRDF product `t`: its survival probability `q` and
/// whether the path survives. Drawn apart from [`course_keep`] where the vertex's own light is known
/// only later (the wavefront's shadow rays are traced after the step).
#[inline]
pub fn course_draw(t: Color, sample: &mut SampleStream) -> (f32, bool) {
    let q = t.max_element().min(1.0);
    (q, q >= 1.0 || sample.rng.next_f32() < q)
}

/// What a vertex of the course's roulette keeps of its own light `e`, added to `l`: `e / q` when the
/// path survives, `e` when it ends.
#[inline]
pub fn course_keep(e: Color, q: f32, survives: bool, l: &mut Color) {
    *l += if survives { e / q } else { e };
}

/// The unbiased roulette after a bounce that left the path with throughput `beta`: the probability `q`
/// of its survival, by which `beta` is to be divided, or `None` when it ends.
#[inline]
pub fn unbiased(beta: Color, sample: &mut SampleStream) -> Option<f32> {
    let q = beta.max_element().min(1.0);
    if sample.rng.next_f32() >= q {
        return None;
    }
    Some(q)
}
