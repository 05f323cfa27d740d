//! The figures of the page's structure chart, measured the way `arbor bench` measures them
//! ([`arbor::bench`]): every structure kind built with its default parameters over the scene, then the
//! same rays traced by each, one primary ray through each pixel centre of the current view and one
//! cosine-weighted diffuse bounce from each hit, in parallel, timed. Brute force traces a deterministic
//! sample of them ([`arbor::bench::sample`]) so that a large mesh does not take hours.
//!
//! Each structure is built afresh for its row, so that its build time, like its ray rates, is measured
//! while the view's passes are held ([`Frames::quiet`]): a build made earlier beside a render would
//! report the render's load too. Runs on a thread of its own, one at a time, reporting each structure
//! as it is done; the view resumes when it ends.

use std::sync::{Arc, Mutex};

use arbor::accel::AccelKind;
use arbor::bench::{diffuse_rays, primary_rays, sample, trace};
use arbor::camera::Camera;
use serde_json::{json, Value};

use crate::frames::Frames;
use crate::structures::{stats_json, Structures};

/// Triangle tests brute force may spend per ray set.
const BRUTE_BUDGET: usize = 200_000_000;

/// The chart's state: not run, running (rows so far), or done.
#[derive(Default)]
pub struct Bench {
    state: Mutex<(String, Vec<Value>)>,
}

impl Bench {
    /// `{"state": ..., "rows": [...]}`.
    pub fn json(&self) -> Value {
        let s = self.state.lock().unwrap_or_else(|e| e.into_inner());
        json!({"state": if s.0.is_empty() { "idle" } else { s.0.as_str() }, "rows": s.1})
    }

    /// Starts measuring every structure through `cam`; `false` when a run is already going.
    pub fn start(
        self: &Arc<Self>,
        structures: Arc<Structures>,
        frames: Arc<Frames>,
        cam: Camera,
        events: crate::structures::Events,
    ) -> bool {
        {
            let mut s = self.state.lock().unwrap_or_else(|e| e.into_inner());
            if s.0 == "running" {
                return false;
            }
            *s = ("running".into(), Vec::new());
        }
        let me = self.clone();
        std::thread::spawn(move || {
            let result = me.run(&structures, &frames, &cam, &events);
            let mut s = me.state.lock().unwrap_or_else(|e| e.into_inner());
            s.0 = match result {
                Ok(()) => "done".into(),
                Err(e) => format!("failed: {e}"),
            };
            let _ = events.send(json!({"type": "bench", "state": s.0}).to_string());
        });
        true
    }

    fn run(
        &self,
        structures: &Structures,
        frames: &Frames,
        cam: &Camera,
        events: &crate::structures::Events,
    ) -> arbor::Result<()> {
        let _quiet = frames.quiet();
        let reference = structures.with_kind(AccelKind::BvhSah)?;
        let primary = primary_rays(cam);
        let (hits, _) = trace(&reference.geometry, &primary);
        let diffuse = diffuse_rays(&reference, &primary, &hits);
        let prims = reference.geometry.counts.triangles + reference.geometry.counts.spheres;
        for &kind in AccelKind::ALL {
            let scene = structures.build_fresh(kind)?;
            let brute = kind == AccelKind::Brute;
            let rate = |rays: &[arbor::math::Ray]| {
                let (rays, _) = if brute {
                    sample(rays, (BRUTE_BUDGET / prims.max(1)).clamp(64, 4096))
                } else {
                    (rays.to_vec(), 1)
                };
                let (_, time) = trace(&scene.geometry, &rays);
                rays.len() as f64 / time.as_secs_f64().max(1e-9) / 1e6
            };
            let row = json!({
                "kind": kind.name(),
                "stats": stats_json(&scene),
                "mrays_primary": rate(&primary),
                "mrays_diffuse": rate(&diffuse),
                "rays_primary": primary.len(),
                "rays_diffuse": diffuse.len(),
                "sampled": brute,
            });
            let _ = events.send(json!({"type": "bench", "state": "running", "row": row}).to_string());
            self.state.lock().unwrap_or_else(|e| e.into_inner()).1.push(row);
        }
        Ok(())
    }
}
