//! `--integrator`, `--path-options` and `--sampler` of `render`: the integrator of every camera, and the
//! path tracer's options, overriding what the scene names (METU `Renderer`, `RendererParams`), and how
//! its random numbers are spread over a pixel's samples.

use arbor::renderer::{PathOptions, Renderer};
use arbor::sampler::SamplerKind;
use clap::Args;

/// The flags.
#[derive(Args, Clone, Debug)]
pub struct IntegratorArgs {
    /// The integrator, overriding the scene's Renderer: whitted, or path (a camera that names no path
    /// tracer options gets importance sampling, next event estimation and MIS).
    #[arg(long, value_enum)]
    pub integrator: Option<IntegratorArg>,
    /// The path tracer's options, overriding the scene's RendererParams: a comma-separated list of
    /// importance, next-event, roulette and mis (mis turns on the first two), or none for the plain path
    /// tracer. Implies --integrator path.
    #[arg(long, value_enum, value_delimiter = ',', value_name = "OPTIONS")]
    pub path_options: Option<Vec<PathOption>>,
    /// The path tracer's samples: stratified (each light and bounce sample spread over the pixel's
    /// samples, in its own random order: less noise for the same samples), or independent (each at
    /// random, as Arbor drew them before). The other integrators are the same with either.
    #[arg(long, value_enum, default_value_t = SamplerArg::Stratified)]
    pub sampler: SamplerArg,
}

/// `--sampler`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SamplerArg {
    /// The light and bounce samples are stratified too.
    Stratified,
    /// Only the sample positions in the pixel are stratified.
    Independent,
}

impl From<SamplerArg> for SamplerKind {
    fn from(s: SamplerArg) -> Self {
        match s {
            SamplerArg::Stratified => SamplerKind::Stratified,
            SamplerArg::Independent => SamplerKind::Independent,
        }
    }
}

/// `--integrator`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum IntegratorArg {
    /// Whitted-style ray tracing.
    Whitted,
    /// Path tracing.
    Path,
}

/// One of `--path-options`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum PathOption {
    /// Bounce directions drawn by the cosine (ImportanceSampling).
    Importance,
    /// Lights sampled at every vertex (NextEventEstimation).
    NextEvent,
    /// Paths ended at random by their throughput (RussianRoulette).
    Roulette,
    /// Light and bounce samples weighted by the power heuristic (MIS).
    Mis,
    /// No option: the plain path tracer.
    None,
}

impl IntegratorArgs {
    /// The renderer for a camera whose scene names `scene`, when the flags override it; `Err` for
    /// `--path-options` with `--integrator whitted`.
    pub fn renderer(&self, scene: Renderer) -> Result<Option<Renderer>, String> {
        let Some(list) = &self.path_options else {
            return Ok(self.integrator.map(|i| match (i, scene) {
                (IntegratorArg::Whitted, _) => Renderer::Whitted,
                (IntegratorArg::Path, Renderer::PathTracing(o)) => Renderer::PathTracing(o),
                (IntegratorArg::Path, Renderer::Whitted) => Renderer::PathTracing(PathOptions::DEFAULT),
            }));
        };
        if self.integrator == Some(IntegratorArg::Whitted) {
            return Err("--path-options sets the path tracer's options; it cannot go with --integrator whitted".into());
        }
        let mut o = PathOptions::default();
        for option in list {
            match option {
                PathOption::Importance => o.importance_sampling = true,
                PathOption::NextEvent => o.next_event = true,
                PathOption::Roulette => o.russian_roulette = true,
                PathOption::Mis => o.mis = true,
                PathOption::None => {}
            }
        }
        Ok(Some(Renderer::PathTracing(o.implied())))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(integrator: Option<IntegratorArg>, path_options: Option<Vec<PathOption>>) -> IntegratorArgs {
        IntegratorArgs { integrator, path_options, sampler: SamplerArg::Independent }
    }

    #[test]
    fn integrator_flags_override_the_scenes_renderer() {
        let scene = Renderer::PathTracing(PathOptions { next_event: true, ..PathOptions::default() });
        assert_eq!(args(None, None).renderer(scene), Ok(None));
        assert_eq!(args(Some(IntegratorArg::Whitted), None).renderer(scene), Ok(Some(Renderer::Whitted)));
        assert_eq!(args(Some(IntegratorArg::Path), None).renderer(scene), Ok(Some(scene)));
        let default = Renderer::PathTracing(PathOptions::DEFAULT);
        assert_eq!(args(Some(IntegratorArg::Path), None).renderer(Renderer::Whitted), Ok(Some(default)));
        // MIS turns on both samplings; `none` is the plain path tracer, over the scene's options.
        let mis = args(None, Some(vec![PathOption::Mis, PathOption::Roulette])).renderer(scene);
        let want = PathOptions { importance_sampling: true, next_event: true, russian_roulette: true, mis: true };
        assert_eq!(mis, Ok(Some(Renderer::PathTracing(want))));
        let plain = args(Some(IntegratorArg::Path), Some(vec![PathOption::None])).renderer(scene);
        assert_eq!(plain, Ok(Some(Renderer::PathTracing(PathOptions::default()))));
        assert!(args(Some(IntegratorArg::Whitted), Some(vec![PathOption::Mis])).renderer(scene).is_err());
    }
}
