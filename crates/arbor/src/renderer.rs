//! Which integrator computes a camera's image, and the options of the path tracer: plain data that the
//! scene file names (METU `Renderer`, `RendererParams`), the CLI may override, and the renderer reads.

/// The integrator of a camera.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Renderer {
    /// Whitted-style recursive ray tracing (the course's first four assignments).
    #[default]
    Whitted,
    /// Path tracing ([`PathOptions`]).
    PathTracing(PathOptions),
}

/// The path tracer's options. All off is the course's plain path tracer: one bounce direction drawn
/// uniformly over the hemisphere, light found only by hitting an emitter, a fixed path length.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PathOptions {
    /// Bounce directions drawn by the cosine instead of uniformly (`ImportanceSampling`).
    pub importance_sampling: bool,
    /// Lights sampled explicitly at every vertex, and emitters met by a bounce not counted again
    /// (`NextEventEstimation`).
    pub next_event: bool,
    /// How paths end: at the recursion limit, or at random by one of the two Russian roulettes
    /// ([`Roulette`]; a METU camera's `RussianRoulette` asks for the course's).
    pub roulette: Roulette,
    /// Light samples and bounce directions both count where they meet an emitter, weighted by the power
    /// heuristic (Veach 1997), instead of discarding the bounce's (`MIS`; implies the two samplings).
    pub mis: bool,
    /// Paths follow every lobe of a refractive surface, and its BRDF bounce too, within
    /// `MaxRecursionDepth`, rather than one lobe picked at random: what the course's renderer does, so
    /// what a METU path-traced camera gets ([`crate::integrator`]'s `split` module).
    pub split_refraction: bool,
}

impl PathOptions {
    /// What `--integrator path` uses for a camera that names no renderer: importance sampling, next
    /// event estimation and multiple importance sampling, paths ended at the recursion limit.
    pub const DEFAULT: PathOptions = PathOptions {
        importance_sampling: true,
        next_event: true,
        roulette: Roulette::Off,
        mis: true,
        split_refraction: false,
    };

    /// These options with what they imply: MIS weighs light samples against importance-sampled bounces,
    /// so it turns both on.
    pub fn implied(self) -> PathOptions {
        if self.mis {
            PathOptions { importance_sampling: true, next_event: true, ..self }
        } else {
            self
        }
    }
}

/// How the path tracer ends a path.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Roulette {
    /// No roulette: a path ends after the scene's `MaxRecursionDepth` bounces.
    #[default]
    Off,
    /// The course's Russian roulette (CENG 795 hw6), what its official images show: at every vertex the
    /// path survives with probability `q = min(1, max(t))`, `t` the product of the BRDF values met
    /// before (no cosine, density or earlier `1/q`); a killed vertex keeps its own light (emission and
    /// light samples) undivided, a surviving one divides it and what follows by `q`. Biased: the
    /// expectation is `Σ (2 - q_k) E_k` over the path's vertices, `E_k` a vertex's own light
    /// (weighted by the path's throughput), where an unbiased estimator gives `Σ E_k`.
    Course,
    /// Arbor's unbiased Russian roulette: after each bounce the path survives with probability
    /// `q = min(1, max(beta))` of its throughput `beta` and is divided by `q`.
    Unbiased,
}
