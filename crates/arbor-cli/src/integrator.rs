//! `--integrator`, `--path-options`, `--roulette` and `--sampler` of `render`: the integrator of every
//! camera, and the path tracer's options, overriding what the scene names (METU `Renderer`,
//! `RendererParams`), and how its random numbers are spread over a pixel's samples.

use arbor::renderer::{PathOptions, Renderer, Roulette};
use arbor::sampler::SamplerKind;
use clap::{Args, ValueEnum};

/// The flags.
#[derive(Args, Clone, Debug)]
pub struct IntegratorArgs {
    /// The integrator, overriding the scene's Renderer: whitted, or path (a camera that names no path
    /// tracer options gets importance sampling, next event estimation and MIS).
    #[arg(long, value_enum)]
    pub integrator: Option<IntegratorArg>,
    /// The path tracer's options, overriding the scene's RendererParams: a comma-separated list of
    /// importance, next-event, roulette (Arbor's unbiased Russian roulette) and mis (mis turns on the
    /// first two), or none for the plain path tracer. Implies --integrator path. A METU camera's own options
    /// follow both lobes of refractive surfaces, as the course's renderer does; these pick one at random.
    #[arg(long, value_enum, value_delimiter = ',', value_name = "OPTIONS")]
    pub path_options: Option<Vec<PathOption>>,
    /// Which Russian roulette the path-traced cameras that have one use. Without it, a camera whose scene
    /// names RussianRoulette gets the course's (as in the course's official images: biased, its
    /// expectation Σ (2 - q_k) E_k over a path's vertices, where E_k is a vertex's own light and q_k its
    /// survival probability, so images come out brighter than the converged answer), and one given
    /// --path-options roulette the unbiased one. Cameras without a roulette end their paths at
    /// MaxRecursionDepth either way.
    #[arg(long, value_enum)]
    pub roulette: Option<RouletteArg>,
    /// The path tracer's samples: stratified (each light and bounce sample spread over the pixel's
    /// samples, in its own random order: less noise for the same samples), independent (each at
    /// random, as Arbor drew them before), or sobol (spread as stratified, each a point of an
    /// Owen-scrambled Sobol sequence: less noise again). The other integrators are the same with
    /// stratified or independent; sobol also places their samples in the pixel.
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
    /// As stratified, but every 2D value (the position in the pixel too) is a point of an
    /// Owen-scrambled Sobol sequence instead of a jittered cell: less noise again where the light
    /// varies smoothly, most at powers of two samples.
    Sobol,
}

impl From<SamplerArg> for SamplerKind {
    fn from(s: SamplerArg) -> Self {
        match s {
            SamplerArg::Stratified => SamplerKind::Stratified,
            SamplerArg::Independent => SamplerKind::Independent,
            SamplerArg::Sobol => SamplerKind::Sobol,
        }
    }
}

/// `--roulette`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum RouletteArg {
    /// The course's (CENG 795 hw6): survival by the product of the BRDF values met, a killed vertex's own
    /// light kept undivided; biased, no depth limit but a safety cap of 256 bounces.
    Course,
    /// Arbor's: survival by the path's throughput, divided by the survival probability; unbiased, to a
    /// cap of 256 bounces.
    Unbiased,
}

impl From<RouletteArg> for Roulette {
    fn from(r: RouletteArg) -> Self {
        match r {
            RouletteArg::Course => Roulette::Course,
            RouletteArg::Unbiased => Roulette::Unbiased,
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
    /// Paths ended at random by their throughput: Arbor's unbiased Russian roulette (--roulette picks).
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
        let chosen = self.options(scene)?;
        let Some(kind) = self.roulette.map(Roulette::from) else { return Ok(chosen) };
        Ok(match chosen.unwrap_or(scene) {
            Renderer::PathTracing(o) if o.roulette != Roulette::Off && o.roulette != kind => {
                Some(Renderer::PathTracing(PathOptions { roulette: kind, ..o }))
            }
            _ => chosen,
        })
    }

    /// The warning for `--roulette` on camera `camera`, whose scene names `scene`, when the camera gets no
    /// Russian roulette for it to pick.
    pub fn roulette_unused(&self, scene: Renderer, camera: &str) -> Option<String> {
        let kind = self.roulette?;
        match self.renderer(scene).ok()?.unwrap_or(scene) {
            Renderer::PathTracing(o) if o.roulette != Roulette::Off => None,
            _ => Some(format!(
                "--roulette {}: camera {camera} has no Russian roulette, its paths end at MaxRecursionDepth (a \
                 path-traced camera gets one from RussianRoulette or --path-options roulette)",
                kind.to_possible_value().map_or("?".into(), |v| v.get_name().to_string())
            )),
        }
    }

    /// [`Self::renderer`] but for `--roulette`.
    fn options(&self, scene: Renderer) -> Result<Option<Renderer>, String> {
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
                PathOption::Roulette => o.roulette = Roulette::Unbiased,
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
        IntegratorArgs { integrator, path_options, roulette: None, sampler: SamplerArg::Independent }
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
        let want = PathOptions {
            importance_sampling: true,
            next_event: true,
            roulette: Roulette::Unbiased,
            mis: true,
            ..PathOptions::default()
        };
        assert_eq!(mis, Ok(Some(Renderer::PathTracing(want))));
        let plain = args(Some(IntegratorArg::Path), Some(vec![PathOption::None])).renderer(scene);
        assert_eq!(plain, Ok(Some(Renderer::PathTracing(PathOptions::default()))));
        assert!(args(Some(IntegratorArg::Whitted), Some(vec![PathOption::Mis])).renderer(scene).is_err());
    }

    #[test]
    fn integrator_roulette_flag_picks_the_kind_of_the_cameras_that_have_one() {
        let course = PathOptions { next_event: true, roulette: Roulette::Course, ..PathOptions::default() };
        let unbiased = PathOptions { roulette: Roulette::Unbiased, ..course };
        let with = |r: RouletteArg, path_options: Option<Vec<PathOption>>| IntegratorArgs {
            roulette: Some(r),
            ..args(None, path_options)
        };
        let scene = Renderer::PathTracing(course);
        assert_eq!(with(RouletteArg::Unbiased, None).renderer(scene), Ok(Some(Renderer::PathTracing(unbiased))));
        // Already the scene's kind: nothing to override.
        assert_eq!(with(RouletteArg::Course, None).renderer(scene), Ok(None));
        // --path-options roulette is the unbiased one, unless --roulette says otherwise.
        let asked = Some(vec![PathOption::NextEvent, PathOption::Roulette]);
        assert_eq!(args(None, asked.clone()).renderer(Renderer::Whitted), Ok(Some(Renderer::PathTracing(unbiased))));
        assert_eq!(with(RouletteArg::Course, asked).renderer(Renderer::Whitted), Ok(Some(scene)));
        // Cameras without a roulette keep their depth limit; Whitted cameras stay Whitted; both are warned of.
        let plain = Renderer::PathTracing(PathOptions::default());
        assert_eq!(with(RouletteArg::Course, None).renderer(plain), Ok(None));
        assert_eq!(with(RouletteArg::Unbiased, None).renderer(Renderer::Whitted), Ok(None));
        let warning = with(RouletteArg::Course, None).roulette_unused(plain, "7").unwrap();
        assert!(warning.starts_with("--roulette course: camera 7 has no Russian roulette"), "{warning}");
        assert!(with(RouletteArg::Unbiased, None).roulette_unused(Renderer::Whitted, "7").is_some());
        assert_eq!(with(RouletteArg::Unbiased, None).roulette_unused(scene, "7"), None);
        assert_eq!(args(None, None).roulette_unused(plain, "7"), None);
    }
}
