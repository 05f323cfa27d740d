//! The API's JSON: reading a view request (every field checked, an error naming the field and what it
//! takes), and writing vectors and the scene's cameras.

use arbor::camera::Camera;
use arbor::integrator::DebugView;
use arbor::math::Vec3;
use arbor::renderer::{PathOptions, Renderer};
use arbor::scene::Scene;
use serde_json::{json, Value};

use crate::frames::ViewRequest;

/// The largest view the page may ask for, per side.
pub const MAX_SIDE: u32 = 4096;
/// The most samples per pixel a view may refine to.
pub const MAX_SPP: u32 = 65536;

/// `[x, y, z]`.
pub fn vec3(v: Vec3) -> Value {
    json!([v.x, v.y, v.z])
}

/// A camera's pose and image, as the page starts from.
pub fn camera_json(index: usize, cam: &Camera) -> Value {
    json!({
        "index": index,
        "id": cam.id,
        "eye": vec3(cam.eye()),
        "gaze": vec3(cam.gaze()),
        "up": vec3(cam.up()),
        "width": cam.width,
        "height": cam.height,
        "samples": cam.num_samples,
        "renderer": match cam.renderer { Renderer::Whitted => "whitted", Renderer::PathTracing(_) => "path" },
    })
}

/// The view a request body asks for: `{"camera", "eye", "gaze", "up", "width", "height", "integrator",
/// "overlay", "spp"}` (only `camera` required; the rest default to the camera's own).
pub fn view_request(body: &Value, scene: &Scene) -> Result<ViewRequest, String> {
    let Value::Object(map) = body else { return Err("the body must be a JSON object".into()) };
    for key in map.keys() {
        if !["camera", "eye", "gaze", "up", "width", "height", "integrator", "overlay", "spp"].contains(&key.as_str()) {
            return Err(format!("unknown field \"{key}\""));
        }
    }
    let index = match body.get("camera") {
        Some(v) => v.as_u64().filter(|&i| (i as usize) < scene.cameras.len()).ok_or_else(|| {
            format!("\"camera\" must be a camera index from 0 to {}", scene.cameras.len().saturating_sub(1))
        })? as usize,
        None => 0,
    };
    let cam = scene.cameras.get(index).ok_or("the scene has no camera")?;
    let eye = vector(body, "eye")?.unwrap_or(cam.eye());
    let gaze = vector(body, "gaze")?.unwrap_or(cam.gaze());
    let up = vector(body, "up")?.unwrap_or(cam.up());
    if gaze.length_squared() == 0.0 || up.length_squared() == 0.0 || gaze.cross(up).length_squared() == 0.0 {
        return Err("\"gaze\" and \"up\" must be non-zero and not parallel".into());
    }
    let side = |key: &str, default: u32| match body.get(key) {
        None => Ok(default),
        Some(v) => v
            .as_u64()
            .filter(|&n| (1..=MAX_SIDE as u64).contains(&n))
            .map(|n| n as u32)
            .ok_or_else(|| format!("\"{key}\" must be a whole number of pixels from 1 to {MAX_SIDE}")),
    };
    let (width, height) = (side("width", cam.width.min(MAX_SIDE))?, side("height", cam.height.min(MAX_SIDE))?);
    let renderer = match body.get("integrator").map(|v| v.as_str()) {
        None => cam.renderer,
        Some(Some("whitted")) => Renderer::Whitted,
        Some(Some("path")) => match cam.renderer {
            Renderer::PathTracing(o) => Renderer::PathTracing(o),
            Renderer::Whitted => Renderer::PathTracing(PathOptions::DEFAULT),
        },
        Some(_) => return Err("\"integrator\" must be \"whitted\" or \"path\"".into()),
    };
    let overlay = match body.get("overlay") {
        None | Some(Value::Null) => None,
        Some(Value::String(s)) if s == "none" => None,
        Some(Value::String(s)) => Some(s.parse::<DebugView>().map_err(|e| format!("\"overlay\": {e}"))?),
        Some(_) => return Err("\"overlay\" must be a string: none, boxes[:DEPTH], heatmap, primid or normal".into()),
    };
    let max_spp = match body.get("spp") {
        None => 64,
        Some(v) => v
            .as_u64()
            .filter(|&n| (1..=MAX_SPP as u64).contains(&n))
            .ok_or_else(|| format!("\"spp\" must be a whole number from 1 to {MAX_SPP}"))? as u32,
    };
    Ok(ViewRequest { camera: index, eye, gaze, up, width, height, renderer, overlay, max_spp })
}

/// The optional vector field `key`: three finite numbers.
fn vector(body: &Value, key: &str) -> Result<Option<Vec3>, String> {
    let Some(v) = body.get(key) else { return Ok(None) };
    let err = || format!("\"{key}\" must be an array of 3 finite numbers");
    let a = v.as_array().filter(|a| a.len() == 3).ok_or_else(err)?;
    let n: Vec<f32> = a.iter().map(|x| x.as_f64().map(|f| f as f32)).collect::<Option<_>>().ok_or_else(err)?;
    if n.iter().any(|x| !x.is_finite()) {
        return Err(err());
    }
    Ok(Some(Vec3::new(n[0], n[1], n[2])))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_vectors_must_be_three_finite_numbers() {
        let body = json!({"eye": [1, 2, 3], "gaze": [1, 2], "up": [0, "1", 0], "x": [1e39, 0, 0]});
        assert_eq!(vector(&body, "eye"), Ok(Some(Vec3::new(1.0, 2.0, 3.0))));
        assert_eq!(vector(&body, "gaze"), Err("\"gaze\" must be an array of 3 finite numbers".into()));
        assert_eq!(vector(&body, "up"), Err("\"up\" must be an array of 3 finite numbers".into()));
        assert_eq!(vector(&body, "x"), Err("\"x\" must be an array of 3 finite numbers".into()));
        assert_eq!(vector(&body, "none"), Ok(None));
    }
}
