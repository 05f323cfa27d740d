//! The scene under its acceleration structures: the current one, which every frame uses, rebuilt in the
//! background when the page asks for another kind or other parameters; and the others, built once each
//! with their default parameters for the comparisons. A rebuild reads the scene's description again
//! ([`arbor::scene::Scene::build`]: the same loader as `arbor render`), so only the scene named on the
//! command line and its assets are ever opened.
//!
//! Invariants: one rebuild at a time (another request gets "busy"); the current scene is swapped whole,
//! so a frame or an inspection in flight keeps the scene it started with. Cost: a structure's build per
//! rebuild; memory: one scene per structure kept.

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, RwLock};
use std::time::{Duration, Instant};

use arbor::accel::{AccelConfig, AccelKind, AccelStats};
use arbor::scene::{Scene, SceneDesc};
use serde_json::{json, Value};
use tokio::sync::broadcast;

/// How often a rebuild in progress reports its elapsed time.
const TICK: Duration = Duration::from_millis(200);

/// The page's notifications (Server-Sent Events): one JSON object each.
pub type Events = broadcast::Sender<String>;

/// The scene's structures.
pub struct Structures {
    desc: SceneDesc,
    current: RwLock<(AccelConfig, Arc<Scene>)>,
    /// Other structures, by kind, with default parameters.
    others: Mutex<BTreeMap<&'static str, Arc<Scene>>>,
    building: AtomicBool,
    events: Events,
}

impl Structures {
    /// `desc` under `config`, built now.
    pub fn new(desc: SceneDesc, config: AccelConfig, events: Events) -> arbor::Result<Structures> {
        let scene = Arc::new(Scene::build(desc.clone(), &config, None)?);
        Ok(Structures {
            desc,
            current: RwLock::new((config, scene)),
            others: Mutex::new(BTreeMap::new()),
            building: AtomicBool::new(false),
            events,
        })
    }

    /// The scene under the current structure.
    pub fn scene(&self) -> Arc<Scene> {
        self.current.read().unwrap_or_else(|e| e.into_inner()).1.clone()
    }

    /// The current structure's configuration.
    pub fn config(&self) -> AccelConfig {
        self.current.read().unwrap_or_else(|e| e.into_inner()).0.clone()
    }

    /// The scene's description (cameras and file names, for the page).
    pub fn desc(&self) -> &SceneDesc {
        &self.desc
    }

    /// Whether a rebuild is running.
    pub fn building(&self) -> bool {
        self.building.load(Ordering::Acquire)
    }

    /// Starts rebuilding the current structure as `config` on a thread of its own; `then` runs once the
    /// new scene is in place. `false` when a rebuild is already running.
    pub fn rebuild(self: &Arc<Self>, config: AccelConfig, then: impl FnOnce() + Send + 'static) -> bool {
        if self.building.swap(true, Ordering::AcqRel) {
            return false;
        }
        let me = self.clone();
        std::thread::spawn(move || {
            let kind = config.kind().name();
            let result = me.build_reporting(&config, "current");
            if let Ok(scene) = &result {
                *me.current.write().unwrap_or_else(|e| e.into_inner()) = (config, scene.clone());
            }
            me.building.store(false, Ordering::Release);
            match result {
                Ok(scene) => {
                    me.emit(json!({"type": "build", "state": "done", "kind": kind, "stats": stats_json(&scene)}));
                    then();
                }
                Err(e) => me.emit(json!({"type": "build", "state": "failed", "kind": kind, "error": e.to_string()})),
            }
        });
        true
    }

    /// The scene under `kind` with default parameters (the current scene when it is that), built now
    /// if it is not yet.
    pub fn with_kind(&self, kind: AccelKind) -> arbor::Result<Arc<Scene>> {
        {
            let current = self.current.read().unwrap_or_else(|e| e.into_inner());
            if current.0 == AccelConfig::from(kind) {
                return Ok(current.1.clone());
            }
        }
        if let Some(s) = self.others.lock().unwrap_or_else(|e| e.into_inner()).get(kind.name()) {
            return Ok(s.clone());
        }
        let scene = self.build_reporting(&AccelConfig::from(kind), "comparison")?;
        self.others.lock().unwrap_or_else(|e| e.into_inner()).insert(kind.name(), scene.clone());
        Ok(scene)
    }

    /// The scene under `kind` with default parameters, built now whether or not it was before, and not
    /// kept (the benchmark's timed build).
    pub fn build_fresh(&self, kind: AccelKind) -> arbor::Result<Arc<Scene>> {
        self.build_reporting(&AccelConfig::from(kind), "benchmark")
    }

    /// Every structure built so far: the current one first, then the others by kind.
    pub fn built(&self) -> Vec<(String, Arc<Scene>)> {
        let (config, scene) = self.current.read().unwrap_or_else(|e| e.into_inner()).clone();
        let mut out = vec![(label(&config), scene)];
        for (kind, s) in self.others.lock().unwrap_or_else(|e| e.into_inner()).iter() {
            if kind.parse::<AccelKind>().ok().map(AccelConfig::from).as_ref() != Some(&config) {
                out.push((kind.to_string(), s.clone()));
            }
        }
        out
    }

    /// Builds `config`, reporting the elapsed time every [`TICK`] while it runs (`purpose`: what for).
    fn build_reporting(&self, config: &AccelConfig, purpose: &str) -> arbor::Result<Arc<Scene>> {
        let kind = config.kind().name();
        let done = Arc::new(AtomicBool::new(false));
        let (ticker_done, events, purpose_owned) = (done.clone(), self.events.clone(), purpose.to_string());
        let start = Instant::now();
        let running = move |ms: f64| {
            json!({"type": "build", "state": "running", "kind": kind, "purpose": purpose_owned, "elapsed_ms": ms})
                .to_string()
        };
        // The first report goes out before the build starts: a build over before the ticker's thread
        // got to run showed no "running" at all.
        let _ = events.send(running(0.0));
        let ticker = std::thread::spawn(move || loop {
            std::thread::park_timeout(TICK);
            if ticker_done.load(Ordering::Acquire) {
                break;
            }
            let _ = events.send(running(start.elapsed().as_secs_f64() * 1e3));
        });
        let scene = Scene::build(self.desc.clone(), config, None).map(Arc::new);
        done.store(true, Ordering::Release);
        ticker.thread().unpark();
        let _ = ticker.join();
        scene
    }

    fn emit(&self, event: Value) {
        // No page listening is not an error.
        let _ = self.events.send(event.to_string());
    }
}

/// `kind` or `kind key=value ...` for a configuration.
pub fn label(config: &AccelConfig) -> String {
    let mut out = config.kind().name().to_string();
    for p in config.params() {
        if let Some(v) = config.get(p.key) {
            out.push_str(&format!(" {}={v}", p.key));
        }
    }
    out
}

/// A structure's statistics as the page shows them.
pub fn stats_json(scene: &Scene) -> Value {
    let s: AccelStats = scene.geometry.accel_stats();
    let triangles = scene.geometry.counts.triangles.max(1);
    json!({
        "kind": s.kind,
        "build_ms": scene.build_time.as_secs_f64() * 1e3,
        "nodes": s.nodes,
        "leaves": s.leaves,
        "max_depth": s.max_depth,
        "mean_depth": s.mean_depth,
        "bytes": s.bytes,
        "bytes_per_triangle": s.bytes as f64 / triangles as f64,
        "sah_cost": s.sah_cost,
        "mean_leaf_prims": s.mean_leaf_prims,
        "refs_per_prim": s.refs_per_prim,
        "triangles": scene.geometry.counts.triangles,
        "spheres": scene.geometry.counts.spheres,
    })
}
