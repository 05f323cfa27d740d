//! Warnings about a scene that renders but probably not as meant: the readers' own (unknown elements,
//! unused properties) and two checks of the description: a scene with no objects (every image is the
//! background) and a camera whose up vector is parallel to its gaze (the image's rotation about the
//! gaze is then undefined).

use arbor::scene::SceneDesc;

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
