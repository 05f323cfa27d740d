//! Warnings about a scene that renders but probably not as meant: the readers' own (unknown elements,
//! unused properties) and three checks of the description: a scene with no objects (every image is the
//! background), a camera whose up vector is parallel to its gaze (the image's rotation about the
//! gaze is then undefined), and a path-traced camera in a scene where no path can find light (every
//! object is black).

use arbor::renderer::Renderer;
use arbor::scene::{CameraDesc, SceneDesc};

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
