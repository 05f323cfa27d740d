//! One pixel's rays, inspected: sample 0 of the pixel under the current view, traced by the renderer
//! itself ([`arbor::render::inspect_sample`], which records every query its integrator makes), then
//! described for the page: each ray's kind and parent, origin, direction, `t`, what it hit (object,
//! triangle, material, barycentric `(u, v)`, point, normal), its segment in pixel coordinates, and the
//! nodes visited and primitives tested by every structure built so far for the same ray.
//!
//! The integrator traces a ray's shadow rays, then its reflections and refractions, depth first, so a
//! ray's parent is the latest hit before it at its origin (the origin is that hit point pushed off the
//! surface). A secondary ray is a reflection when it leaves on the side its parent arrived from, else a
//! refraction; the path tracer's are bounces. Traversal counts are of the closest-hit query (a shadow
//! ray's any-hit query stops at its first hit, so it does at most that work).

use arbor::accel::TraversalCounts;
use arbor::integrator::debug::prim_color;
use arbor::integrator::RayEvent;
use arbor::math::{Ray, Vec3};
use arbor::render::{inspect_sample, RenderOptions};
use arbor::renderer::Renderer;
use arbor::scene::Scene;
use serde_json::{json, Value};

use crate::frames::ViewRequest;
use crate::json::vec3;
use crate::structures::Structures;

/// The description of pixel `(x, y)` of `view`'s image.
pub fn inspect(structures: &Structures, view: &ViewRequest, x: u32, y: u32) -> Value {
    let scene = structures.scene();
    let cam = scene.cameras[view.camera].posed(view.eye, view.gaze, view.up, view.width, view.height);
    // Sample 0 with seed 0: the first full-resolution pass of the view's render.
    let opts = RenderOptions { spp: Some(1), renderer: Some(view.renderer), ..Default::default() };
    let (color, events) = inspect_sample(&scene, &cam, &opts, (x, y, 0));
    let built = structures.built();
    let far = 2.0 * scene.geometry.bounds().extent().length().max(1.0);
    let path = matches!(view.renderer, Renderer::PathTracing(_));
    let rays: Vec<Value> = events
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let parent = (i > 0).then(|| parent_of(&events[..i], e.ray.origin)).flatten();
            let kind = match (i, e.occluded, parent) {
                (0, _, _) => "camera",
                (_, Some(_), _) => "shadow",
                _ if path => "bounce",
                (_, _, Some(p)) if leaves_back(&scene, &events[p], &e.ray) => "reflection",
                (_, _, Some(_)) => "refraction",
                _ => "secondary",
            };
            let end = match (e.hit, e.occluded) {
                (Some(h), _) => e.ray.at(h.t),
                (None, Some(_)) if e.t_max.is_finite() => e.ray.at(e.t_max),
                _ => e.ray.origin + e.ray.dir.normalize_or_zero() * far,
            };
            let segment = cam.project_segment(e.ray.origin, end).map(|(p, q)| json!([p.x, p.y, q.x, q.y]));
            let counts: Vec<Value> = built
                .iter()
                .map(|(label, s)| {
                    let mut c = TraversalCounts::default();
                    s.geometry.intersect_counted(&e.ray, e.t_max, &mut c);
                    json!({"structure": label, "nodes": c.nodes, "prims": c.prims})
                })
                .collect();
            json!({
                "index": i,
                "kind": kind,
                "parent": parent,
                "origin": vec3(e.ray.origin),
                "direction": vec3(e.ray.dir),
                "t_max": finite(e.t_max),
                "occluded": e.occluded,
                "hit": e.hit.map(|h| hit_json(structures, &scene, &e.ray, &h)),
                "segment": segment,
                "counts": counts,
            })
        })
        .collect();
    json!({"x": x, "y": y, "radiance": vec3(color), "rays": rays})
}

/// The latest closest-hit event in `before` whose hit point is nearest `origin`.
fn parent_of(before: &[RayEvent], origin: Vec3) -> Option<usize> {
    let mut best: Option<(usize, f32)> = None;
    for (j, e) in before.iter().enumerate().rev() {
        if let Some(h) = e.hit {
            let d = (e.ray.at(h.t) - origin).length();
            if best.is_none_or(|(_, b)| d < b) {
                best = Some((j, d));
            }
        }
    }
    best.map(|(j, _)| j)
}

/// Whether `ray` leaves its parent's hit on the side the parent's ray arrived from (a reflection).
fn leaves_back(scene: &Scene, parent: &RayEvent, ray: &Ray) -> bool {
    let Some(h) = parent.hit else { return true };
    let n = scene.surface(&parent.ray, &h).ng;
    (ray.dir.dot(n) > 0.0) == (parent.ray.dir.dot(n) < 0.0)
}

/// What a ray hit, for the inspector's table.
fn hit_json(structures: &Structures, scene: &Scene, ray: &Ray, h: &arbor::accel::Hit) -> Value {
    let s = scene.surface(ray, h);
    let desc = structures.desc();
    let object = desc.objects.get(s.object as usize);
    let prim = scene.geometry.global_prim_id(h);
    let triangle = object.is_some_and(|o| matches!(o.shape, arbor::scene::ShapeDesc::Mesh { .. }));
    json!({
        "t": h.t,
        "object": s.object,
        "object_name": object.map(|o| o.name.clone()),
        "triangle": triangle.then_some(h.sub),
        "prim_id": prim,
        "prim_color": vec3(prim_color(prim)),
        "material": s.material,
        "material_id": desc.materials.get(s.material).map(|m| m.id.clone()),
        "u": h.u,
        "v": h.v,
        "point": vec3(s.p),
        "normal": vec3(s.ng.normalize_or_zero()),
    })
}

/// `v`, or `null` when it is not finite (JSON has no infinity).
fn finite(v: f32) -> Value {
    if v.is_finite() {
        json!(v)
    } else {
        Value::Null
    }
}
