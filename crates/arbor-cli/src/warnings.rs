//! Warnings about a scene that renders but probably not as meant: the readers' own (unknown elements,
//! unused properties) and two checks of the description: a scene with no objects (every image is the
//! background) and a camera whose up vector is parallel to its gaze (the image's rotation about the
//! gaze is then undefined). Once the scene is built, one check of what the cameras see: an unculled
//! image most of whose camera rays meet back faces (a scene made for back-face culling, which the XML
//! form cannot say it is: [`back_faces`]).

use arbor::render::{back_face_share, BACK_FACE_WARNING_SHARE};
use arbor::scene::{Scene, SceneDesc};
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
