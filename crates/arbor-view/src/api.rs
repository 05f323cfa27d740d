//! The routes (`docs/view.md` lists them with their bodies and answers) and the checks every request
//! passes first: the `Host` header names this server (a web page on another name cannot reach it through
//! DNS rebinding), and the token is there, as `?token=` or an `X-Arbor-Token` header (a local user or a
//! page that does not know it can do nothing). Bodies are JSON of at most [`MAX_BODY`] bytes; a bad
//! request is a 4xx with `{"error": "..."}`, never a panic; a body that does not arrive whole within
//! the header deadline (`listener::HEADER_TIMEOUT`, 10 s) of its headers is a 408, so a client that sends a body slowly or not
//! at all cannot hold a connection slot.  Heavy requests (inspecting a pixel, the
//! side-by-side heatmaps) take one of [`HEAVY`] slots or get 503; event streams one of [`STREAMS`].

use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use arbor::accel::{AccelConfig, AccelKind};
use arbor::integrator::DebugView;
use arbor::render::{render_camera, RenderOptions};
use axum::body::{Body, Bytes};
use axum::extract::rejection::BytesRejection;
use axum::extract::{DefaultBodyLimit, FromRequest, Query, Request, State};
use axum::http::{header, HeaderValue, StatusCode};
use axum::middleware::{self, Next};
use axum::response::sse::{Event, KeepAlive, Sse};
use axum::response::{Html, IntoResponse, Response};
use axum::routing::{get, post};
use axum::Router;
use futures_util::StreamExt;
use serde_json::{json, Value};
use tokio::sync::{broadcast, Semaphore};

use crate::bench::Bench;
use crate::frames::{Frames, Image};
use crate::json::{camera_json, view_request, MAX_SIDE, MAX_SPP};
use crate::structures::{label, stats_json, Structures};

/// The largest request body, in bytes.
pub const MAX_BODY: usize = 16 * 1024;
/// Heavy requests at once.
pub const HEAVY: usize = 2;
/// Event streams open at once.
pub const STREAMS: usize = 8;
/// The longest a request waits for a new image.
const LONGEST_WAIT: Duration = Duration::from_secs(20);

/// The page: HTML with its style and script inlined, so that one request (with the token) brings all.
const PAGE: &str = concat!(
    include_str!("page/head.html"),
    "<style>\n",
    include_str!("page/app.css"),
    "</style>\n",
    include_str!("page/body.html"),
    "<script>\n",
    include_str!("page/app.js"),
    "</script>\n</body>\n</html>\n"
);

/// What every route shares.
pub(crate) struct App {
    pub(crate) structures: Arc<Structures>,
    pub(crate) frames: Arc<Frames>,
    pub(crate) bench: Arc<Bench>,
    pub(crate) events: broadcast::Sender<String>,
    pub(crate) token: String,
    pub(crate) hosts: Vec<String>,
    pub(crate) heavy: Arc<Semaphore>,
    pub(crate) streams: Arc<Semaphore>,
    pub(crate) compared: Mutex<HashMap<String, Arc<Image>>>,
}

pub(crate) type Shared = Arc<App>;

/// An error answer: a status and a message.
pub struct ApiError(StatusCode, String);

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        let mut r = (self.0, json!({ "error": self.1 }).to_string()).into_response();
        r.headers_mut().insert(header::CONTENT_TYPE, HeaderValue::from_static("application/json"));
        r
    }
}

fn bad(msg: impl Into<String>) -> ApiError {
    ApiError(StatusCode::BAD_REQUEST, msg.into())
}

fn ok_json(v: Value) -> Response {
    ([(header::CONTENT_TYPE, "application/json"), (header::CACHE_CONTROL, "no-store")], v.to_string()).into_response()
}

/// Every route, behind the host and token checks.
pub(crate) fn routes(app: Shared) -> Router {
    Router::new()
        .route("/", get(page))
        .route("/api/scene", get(scene))
        .route("/api/view", post(set_view))
        .route("/api/image", get(image))
        .route("/api/events", get(events))
        .route("/api/inspect", get(inspect))
        .route("/api/accel", post(rebuild))
        .route("/api/compare", get(compare))
        .route("/api/compare/image", get(compare_image))
        .route("/api/bench", get(bench_state).post(bench_start))
        .fallback(|| async { ApiError(StatusCode::NOT_FOUND, "no such page or endpoint".into()) })
        // The router adds the `Allow` header.
        .method_not_allowed_fallback(|method: axum::http::Method, uri: axum::http::Uri| async move {
            ApiError(StatusCode::METHOD_NOT_ALLOWED, format!("{method} is not allowed on {}", uri.path()))
        })
        .layer(middleware::from_fn_with_state(app.clone(), guard))
        .layer(DefaultBodyLimit::max(MAX_BODY))
        .with_state(app)
}

/// The checks before any route: the host, then the token.
async fn guard(State(app): State<Shared>, request: Request, next: Next) -> Response {
    let host = request.headers().get(header::HOST).and_then(|h| h.to_str().ok()).unwrap_or("");
    if !app.hosts.iter().any(|h| h == host) {
        return ApiError(StatusCode::FORBIDDEN, format!("host '{host}' is not this server")).into_response();
    }
    let query = request.uri().query().unwrap_or("");
    let from_query = query.split('&').find_map(|kv| kv.strip_prefix("token="));
    let from_header = request.headers().get("x-arbor-token").and_then(|h| h.to_str().ok());
    let given = from_header.or(from_query).unwrap_or("");
    if !same(given.as_bytes(), app.token.as_bytes()) {
        return ApiError(StatusCode::FORBIDDEN, "a valid token is required (open the URL arbor view printed)".into())
            .into_response();
    }
    next.run(request).await
}

/// Equality in time that does not depend on where the strings differ.
fn same(a: &[u8], b: &[u8]) -> bool {
    a.len() == b.len() && a.iter().zip(b).fold(0u8, |acc, (x, y)| acc | (x ^ y)) == 0
}

async fn page() -> Response {
    let mut r = Html(PAGE).into_response();
    r.headers_mut().insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    r
}

async fn scene(State(app): State<Shared>) -> Response {
    let s = app.structures.scene();
    let desc = app.structures.desc();
    let kinds: Vec<Value> = AccelKind::ALL
        .iter()
        .map(|&k| {
            let config = AccelConfig::from(k);
            let params: Vec<Value> = config
                .params()
                .iter()
                .map(|p| {
                    json!({"key": p.key, "about": p.about, "range": p.range.to_string(),
                    "default": config.get(p.key).map(|v| v.to_string())})
                })
                .collect();
            json!({"kind": k.name(), "params": params})
        })
        .collect();
    let config = app.structures.config();
    let params: serde_json::Map<String, Value> = config
        .params()
        .iter()
        .filter_map(|p| config.get(p.key).map(|v| (p.key.to_string(), json!(v.to_string()))))
        .collect();
    ok_json(json!({
        "scene": desc.source.display().to_string(),
        "cameras": s.cameras.iter().enumerate().map(|(i, c)| camera_json(i, c)).collect::<Vec<_>>(),
        "bounds": {"min": crate::json::vec3(s.geometry.bounds().min), "max": crate::json::vec3(s.geometry.bounds().max)},
        "structure": {"label": label(&config), "kind": config.kind().name(), "params": params, "stats": stats_json(&s),
            "building": app.structures.building()},
        "kinds": kinds,
        "limits": {"max_side": MAX_SIDE, "max_spp": MAX_SPP},
        "view": app.frames.current().map(|(v, _)| v),
    }))
}

/// Reads a JSON body: at most [`MAX_BODY`] bytes (413 beyond), well framed (400 if not), whole within
/// the headers' deadline (408 if not), JSON.
async fn body_json(request: Request) -> Result<Value, ApiError> {
    let deadline = crate::listener::HEADER_TIMEOUT;
    let body = tokio::time::timeout(deadline, Bytes::from_request(request, &())).await.map_err(|_| {
        ApiError(StatusCode::REQUEST_TIMEOUT, format!("the body did not arrive within {} s", deadline.as_secs()))
    })?;
    let body = body.map_err(|e: BytesRejection| match e.status() {
        StatusCode::PAYLOAD_TOO_LARGE => {
            ApiError(StatusCode::PAYLOAD_TOO_LARGE, format!("the body is larger than {MAX_BODY} bytes"))
        }
        status => ApiError(status, format!("the body could not be read: {}", e.body_text())),
    })?;
    serde_json::from_slice(&body).map_err(|e| bad(format!("the body is not JSON: {e}")))
}

async fn set_view(State(app): State<Shared>, request: Request) -> Result<Response, ApiError> {
    let request = view_request(&body_json(request).await?, &app.structures.scene()).map_err(bad)?;
    let view = app.frames.set_view(request);
    Ok(ok_json(json!({ "view": view })))
}

/// A whole number from the query.
fn number(q: &HashMap<String, String>, key: &str) -> Result<Option<u64>, ApiError> {
    q.get(key)
        .map(|v| v.parse::<u64>().map_err(|_| bad(format!("'{key}' must be a whole number, not '{v}'"))))
        .transpose()
}

/// The last image of a channel newer than `after`, waiting for one up to `wait` ms (at most 20 s):
/// 8-bit RGB with its size and figures in headers, or 204 when none came.
async fn image(State(app): State<Shared>, Query(q): Query<HashMap<String, String>>) -> Result<Response, ApiError> {
    let channel = match q.get("channel").map(String::as_str) {
        None | Some("render") => &app.frames.render,
        Some("overlay") => &app.frames.overlay,
        Some(other) => return Err(bad(format!("'channel' must be render or overlay, not '{other}'"))),
    };
    let after = number(&q, "after")?.unwrap_or(0);
    let wait = Duration::from_millis(number(&q, "wait")?.unwrap_or(LONGEST_WAIT.as_millis() as u64)).min(LONGEST_WAIT);
    let mut rx = channel.subscribe();
    let newer = |rx: &tokio::sync::watch::Receiver<Option<Arc<Image>>>| rx.borrow().clone().filter(|i| i.seq > after);
    let found = match newer(&rx) {
        Some(i) => Some(i),
        None => tokio::time::timeout(wait, async {
            loop {
                if rx.changed().await.is_err() {
                    return None;
                }
                if let Some(i) = newer(&rx) {
                    return Some(i);
                }
            }
        })
        .await
        .ok()
        .flatten(),
    };
    Ok(match found {
        Some(i) => image_response(&i),
        None => StatusCode::NO_CONTENT.into_response(),
    })
}

fn image_response(i: &Image) -> Response {
    let mut r = Response::new(Body::from(i.rgb.clone()));
    let h = r.headers_mut();
    let mut put = |k: &'static str, v: String| {
        if let Ok(v) = HeaderValue::from_str(&v) {
            h.insert(k, v);
        }
    };
    put("content-type", "application/octet-stream".into());
    put("cache-control", "no-store".into());
    put("x-seq", i.seq.to_string());
    put("x-view", i.view.to_string());
    put("x-width", i.width.to_string());
    put("x-height", i.height.to_string());
    put("x-samples", i.samples.to_string());
    put("x-render-ms", format!("{:.3}", i.render_ms));
    put("x-mrays", format!("{:.3}", i.mrays));
    put("x-convert-ms", format!("{:.3}", i.convert_ms));
    if let Some(m) = i.heatmap_max {
        put("x-heatmap-max", m.to_string());
    }
    r
}

/// Server-Sent Events: every notification as JSON, starting with `{"type": "hello"}`.
async fn events(State(app): State<Shared>) -> Result<Response, ApiError> {
    let permit = app
        .streams
        .clone()
        .try_acquire_owned()
        .map_err(|_| ApiError(StatusCode::SERVICE_UNAVAILABLE, "too many event streams open".into()))?;
    let rx = app.events.subscribe();
    let hello = futures_util::stream::once(async {
        Ok::<_, std::convert::Infallible>(Event::default().data(r#"{"type":"hello"}"#))
    });
    let stream = tokio_stream::wrappers::BroadcastStream::new(rx).filter_map(move |m| {
        let _held = &permit;
        // A listener too slow to keep up skips what it missed.
        std::future::ready(m.ok().map(|text| Ok(Event::default().data(text))))
    });
    Ok(Sse::new(hello.chain(stream)).keep_alive(KeepAlive::default()).into_response())
}

/// Runs `work` on a blocking thread if a heavy slot is free. The work holds the slot until it ends: a
/// client that goes away drops the request, not the work, which must not make room for more.
async fn heavy<T: Send + 'static>(app: &Shared, work: impl FnOnce() -> T + Send + 'static) -> Result<T, ApiError> {
    let permit = app
        .heavy
        .clone()
        .try_acquire_owned()
        .map_err(|_| ApiError(StatusCode::SERVICE_UNAVAILABLE, "busy: try again".into()))?;
    tokio::task::spawn_blocking(move || {
        let _held = permit;
        work()
    })
    .await
    .map_err(|e| ApiError(StatusCode::INTERNAL_SERVER_ERROR, e.to_string()))
}

async fn inspect(State(app): State<Shared>, Query(q): Query<HashMap<String, String>>) -> Result<Response, ApiError> {
    let (x, y) = (
        number(&q, "x")?.ok_or_else(|| bad("'x' is required"))?,
        number(&q, "y")?.ok_or_else(|| bad("'y' is required"))?,
    );
    let (_, view) = app
        .frames
        .current()
        .ok_or_else(|| ApiError(StatusCode::CONFLICT, "no view yet: POST /api/view first".into()))?;
    if x >= view.width as u64 || y >= view.height as u64 {
        return Err(bad(format!("pixel ({x}, {y}) is outside the {}x{} view", view.width, view.height)));
    }
    let structures = app.structures.clone();
    let v = heavy(&app, move || crate::inspect::inspect(&structures, &view, x as u32, y as u32)).await?;
    Ok(ok_json(v))
}

async fn rebuild(State(app): State<Shared>, request: Request) -> Result<Response, ApiError> {
    let body = body_json(request).await?;
    let kind =
        body.get("kind").and_then(Value::as_str).ok_or_else(|| bad("\"kind\" (a structure name) is required"))?;
    let kind: AccelKind = kind.parse().map_err(|e| bad(format!("\"kind\": {e}")))?;
    let mut config = AccelConfig::from(kind);
    if let Some(params) = body.get("params") {
        let Value::Object(params) = params else { return Err(bad("\"params\" must be an object of key: value")) };
        for (key, value) in params {
            let text = match value {
                Value::String(s) => s.clone(),
                Value::Number(n) => n.to_string(),
                _ => return Err(bad(format!("parameter '{key}' must be a number or a word"))),
            };
            config.set(key, &text).map_err(|e| bad(e.to_string()))?;
        }
    }
    let frames = app.frames.clone();
    if !app.structures.rebuild(config.clone(), move || frames.restart()) {
        return Err(ApiError(StatusCode::CONFLICT, "a rebuild is running".into()));
    }
    Ok((
        StatusCode::ACCEPTED,
        [(header::CONTENT_TYPE, "application/json")],
        json!({"building": label(&config)}).to_string(),
    )
        .into_response())
}

/// Heatmaps of two structures through the current view on one colour scale (the larger maximum).
async fn compare(State(app): State<Shared>, Query(q): Query<HashMap<String, String>>) -> Result<Response, ApiError> {
    let kind = |key: &str| -> Result<AccelKind, ApiError> {
        q.get(key)
            .ok_or_else(|| bad(format!("'{key}' (a structure name) is required")))?
            .parse()
            .map_err(|e| bad(format!("'{key}': {e}")))
    };
    let (a, b) = (kind("a")?, kind("b")?);
    let (_, view) = app
        .frames
        .current()
        .ok_or_else(|| ApiError(StatusCode::CONFLICT, "no view yet: POST /api/view first".into()))?;
    let worker = app.clone();
    let result = heavy(&app, move || -> arbor::Result<Value> {
        let mut out = Vec::new();
        for kind in [a, b] {
            let scene = worker.structures.with_kind(kind)?;
            let cam = scene.cameras[view.camera].posed(view.eye, view.gaze, view.up, view.width, view.height);
            out.push((kind, scene, cam));
        }
        let heat = |scene: &arbor::scene::Scene, cam: &arbor::camera::Camera, scale: Option<u32>| {
            let opts = RenderOptions { debug: Some(DebugView::Heatmap), heatmap_scale: scale, ..Default::default() };
            render_camera(scene, cam, &opts, &|_, _| {})
        };
        let maxima = out
            .iter()
            .map(|(_, s, c)| heat(s, c, None).map(|r| r.1.heatmap_max.unwrap_or(0)))
            .collect::<arbor::Result<Vec<_>>>()?;
        let scale = maxima.iter().copied().max().unwrap_or(0).max(1);
        let mut rows = Vec::new();
        for ((kind, scene, cam), max) in out.iter().zip(maxima) {
            let (film, stats) = heat(scene, cam, Some(scale))?;
            let image = Image {
                seq: 0,
                view: 0,
                width: film.width,
                height: film.height,
                rgb: film.to_rgb8(),
                samples: 1,
                render_ms: stats.time.as_secs_f64() * 1e3,
                mrays: stats.mrays_per_s(),
                convert_ms: 0.0,
                heatmap_max: Some(max),
            };
            worker.compared.lock().unwrap_or_else(|e| e.into_inner()).insert(kind.name().to_string(), Arc::new(image));
            rows.push(json!({"kind": kind.name(), "max": max, "stats": stats_json(scene)}));
        }
        Ok(json!({"scale": scale, "structures": rows}))
    })
    .await?
    .map_err(|e| ApiError(StatusCode::INTERNAL_SERVER_ERROR, e.to_string()))?;
    Ok(ok_json(result))
}

async fn compare_image(
    State(app): State<Shared>,
    Query(q): Query<HashMap<String, String>>,
) -> Result<Response, ApiError> {
    let kind = q.get("kind").ok_or_else(|| bad("'kind' is required"))?;
    let image = app.compared.lock().unwrap_or_else(|e| e.into_inner()).get(kind).cloned();
    image
        .map(|i| image_response(&i))
        .ok_or_else(|| ApiError(StatusCode::NOT_FOUND, format!("no heatmap of '{kind}': GET /api/compare first")))
}

async fn bench_state(State(app): State<Shared>) -> Response {
    ok_json(app.bench.json())
}

async fn bench_start(State(app): State<Shared>) -> Result<Response, ApiError> {
    let (_, view) = app
        .frames
        .current()
        .ok_or_else(|| ApiError(StatusCode::CONFLICT, "no view yet: POST /api/view first".into()))?;
    let scene = app.structures.scene();
    let cam = scene.cameras[view.camera].posed(view.eye, view.gaze, view.up, view.width, view.height);
    if !app.bench.start(app.structures.clone(), app.frames.clone(), cam, app.events.clone()) {
        return Err(ApiError(StatusCode::CONFLICT, "the benchmark is running".into()));
    }
    Ok((StatusCode::ACCEPTED, [(header::CONTENT_TYPE, "application/json")], r#"{"state":"running"}"#).into_response())
}
