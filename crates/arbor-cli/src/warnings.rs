//! Warnings about a scene that renders but probably not as meant: the readers' own (unknown elements,
//! unused properties) and three checks of the description: a scene with no objects (every image is the
//! background), a camera whose up vector is parallel to its gaze (the image's rotation about the
//! gaze is then undefined), and a path-traced camera in a scene where no path can find light (every
//! object is black). Once the scene is built, checks of what the cameras see: an unculled image most
//! of whose camera rays meet back faces (a scene made for back-face culling, which the XML form cannot
//! say it is: [`back_faces`]); and two about Whitted ray trees too large for their budget
//! ([`arbor::integrator::TreePlan`]): before the render, when a sample may need more rays than it allows,
//! and after it, when samples did.

use arbor::integrator::{TreePlan, TREE_BUDGET};
use arbor::render::{back_face_share, RenderStats, BACK_FACE_WARNING_SHARE};
use arbor::renderer::Renderer;
use arbor::scene::{CameraDesc, Scene, SceneDesc};
use arbor::Location;

/// Every warning about `desc`, in file order of the readers' and then the checks'.
pub fn scene_warnings(desc: &SceneDesc) -> Vec<String> {
    let mut out = desc.warnings.clone();
    if desc.objects.is_empty() {
        out.push(format!("{}: the scene has no objects: every image shows only the background", desc.source.display()));
    }
    for cam in &desc.cameras {
        let (gaze, up) = (cam.transform.vector(cam.gaze), cam.transform.vector(cam.up));
        // Relative, so that the scale of the vectors does not matter; a zero vector counts as parallel.
        if gaze.cross(up).length() <= 1e-6 * gaze.length() * up.length() {
            out.push(format!(
                "{}: Camera {}: Up {} is parallel to Gaze {}: the image's orientation is undefined",
                cam.loc, cam.id, cam.up, cam.gaze
            ));
        }
    }
    out
}

/// The warning before rendering `scene` (named `name`) with the Whitted integrator, if a camera
/// sample's ray tree may need more rays than [`TREE_BUDGET`].
pub fn tree_warning(name: &str, scene: &Scene) -> Option<String> {
    TreePlan::of(scene).warning().map(|w| format!("{name}: {w}"))
}

/// The warning after an image of `camera` (`pixels` rendered) whose samples reached their ray-tree
/// budget, if any did.
pub fn capped_warning(name: &str, camera: &str, stats: &RenderStats, pixels: u64) -> Option<String> {
    let total = pixels * stats.samples.1.saturating_sub(stats.samples.0) as u64;
    (stats.capped_samples > 0).then(|| {
        format!(
            "{name}: Camera {camera}: {} of {total} samples needed more than {TREE_BUDGET} rays and dropped \
             their lightest branches",
            stats.capped_samples
        )
    })
}

/// A warning when `cam` is path traced (`renderer`, its own or the command line's) and no path can bring
/// light: the path tracer has no ambient term, and takes light only from emitters and an environment
/// map its rays meet, and, with next event estimation, from the lights no ray can meet (point, spot,
/// directional, area). `env_given`: an environment map from the command line. A scene without objects
/// has its own warning.
pub fn dark_path_tracing(desc: &SceneDesc, cam: &CameraDesc, renderer: Renderer, env_given: bool) -> Option<String> {
    let Renderer::PathTracing(options) = renderer else { return None };
    let emitter = desc.objects.iter().any(|o| o.emission.is_some());
    if desc.objects.is_empty() || emitter || env_given || desc.environment.is_some() {
        return None;
    }
    let why = if desc.lights.is_empty() {
        "the scene has no light, no emitter and no environment map".to_string()
    } else if !options.next_event {
        "without NextEventEstimation it takes no light from point, spot, directional or area lights, and the \
         scene has no emitter or environment map (NextEventEstimation in RendererParams, or --path-options \
         next-event, samples them)"
            .to_string()
    } else {
        return None;
    };
    Some(format!("{}: Camera {}: the path tracer finds no light: {why}; every object renders black", cam.loc, cam.id))
}

/// A warning for each of `cameras` (indices into `scene.cameras`, declared at `locs`) most of whose
/// camera rays meet back faces, when nothing chose the culling (`--cull`/`--no-cull`, the scene's
/// `BackfaceCulling`, its form's default) and the render is therefore unculled.
pub fn back_faces(scene: &Scene, cameras: &[usize], locs: &[Location], cull: Option<bool>) -> Vec<String> {
    if cull.or(scene.cull_backfaces).is_some() {
        return Vec::new();
    }
    let mut out = Vec::new();
    for &c in cameras {
        let share = back_face_share(scene, c);
        if share > BACK_FACE_WARNING_SHARE {
            out.push(format!(
                "{}: Camera {}: {:.0}% of camera rays meet back faces; if the scene expects back-face culling, \
                 render with --cull",
                locs[c],
                scene.cameras[c].id,
                share * 100.0
            ));
        }
    }
    out
}
