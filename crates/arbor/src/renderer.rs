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
    /// Paths ended at random in proportion to their throughput instead of at the recursion limit
    /// (`RussianRoulette`).
    pub russian_roulette: bool,
    /// Light samples and bounce directions both count where they meet an emitter, weighted by the power
    /// heuristic (Veach 1997), instead of discarding the bounce's (`MIS`; implies the two samplings).
    pub mis: bool,
}

impl PathOptions {
    /// What `--integrator path` uses for a camera that names no renderer: importance sampling, next
    /// event estimation and multiple importance sampling, Russian roulette after the recursion limit.
    pub const DEFAULT: PathOptions =
        PathOptions { importance_sampling: true, next_event: true, russian_roulette: false, mis: true };

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
