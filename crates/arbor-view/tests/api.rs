//! The API's surface: every endpoint answers, every request needs the token and this server's `Host`,
//! and bad requests (parameters, bodies, routes, methods) get a 4xx with a message, never a panic.
//! The behaviour behind the endpoints (frames, rebuilds, inspection, comparisons) is in `live.rs`.

mod common;

use arbor::accel::AccelKind;
use common::*;
use serde_json::Value;

/// Every route, as (method, path, body).
const ROUTES: &[(&str, &str, Option<&str>)] = &[
    ("GET", "/", None),
    ("GET", "/api/scene", None),
    ("POST", "/api/view", Some(r#"{"camera": 0}"#)),
    ("GET", "/api/image?wait=0", None),
    ("GET", "/api/events", None),
    ("GET", "/api/inspect?x=0&y=0", None),
    ("POST", "/api/accel", Some(r#"{"kind": "octree"}"#)),
    ("GET", "/api/compare?a=octree&b=kdtree", None),
    ("GET", "/api/compare/image?kind=octree", None),
    ("GET", "/api/bench", None),
    ("POST", "/api/bench", Some("")),
    ("GET", "/no/such/page", None),
];

/// `path` with `token=...` added to its query.
fn with_query_token(path: &str, token: &str) -> String {
    format!("{path}{}token={token}", if path.contains('?') { "&" } else { "?" })
}

#[test]
fn the_page_is_served_whole_from_the_binary() {
    let server = start();
    let r = get(&server, "/");
    assert_eq!(r.status, 200);
    assert_eq!(r.header("content-type"), Some("text/html; charset=utf-8"));
    assert_eq!(r.header("cache-control"), Some("no-store"));
    let page = String::from_utf8(r.body).unwrap();
    // Style and script inlined: one request with the token brings everything.
    for part in
        ["<style>", "<script>", "async function api(", "id=\"render\"", "id=\"inspector\"", "id=\"bench-chart\""]
    {
        assert!(page.contains(part), "the page has {part}");
    }
    assert!(!page.contains("src=\"http") && !page.contains("href=\"http"), "the page loads nothing from the network");
}

#[test]
fn scene_describes_cameras_structures_and_limits() {
    let server = start();
    let r = get(&server, "/api/scene");
    assert_eq!(r.status, 200);
    assert_eq!(r.header("content-type"), Some("application/json"));
    let s = r.json();
    assert!(s["scene"].as_str().unwrap().ends_with("cornell_box.xml"));
    let cam = &s["cameras"][0];
    assert_eq!((cam["index"].as_u64(), cam["id"].as_str()), (Some(0), Some("1")));
    assert_eq!(cam["eye"], serde_json::json!([0.0, 0.0, 20.0]));
    assert_eq!(cam["gaze"], serde_json::json!([0.0, 0.0, -1.0]));
    assert_eq!(
        (cam["width"].as_u64(), cam["height"].as_u64(), cam["samples"].as_u64()),
        (Some(400), Some(400), Some(4))
    );
    assert_eq!(cam["renderer"], "whitted");
    assert_eq!(s["bounds"]["min"], serde_json::json!([-10.0, -10.0, -10.0]));
    let kinds: Vec<&str> = s["kinds"].as_array().unwrap().iter().map(|k| k["kind"].as_str().unwrap()).collect();
    assert_eq!(kinds, AccelKind::ALL.iter().map(|k| k.name()).collect::<Vec<_>>());
    let octree = &s["kinds"][1]["params"];
    assert_eq!(octree[0]["key"], "leaf");
    assert_eq!((octree[0]["range"].as_str(), octree[0]["default"].as_str()), (Some(">= 1"), Some("8")));
    let structure = &s["structure"];
    assert_eq!(structure["kind"], "bvh-sah");
    assert_eq!(structure["building"], false);
    assert_eq!(structure["params"]["leaf"], "8");
    let stats = built(AccelKind::BvhSah).geometry.accel_stats();
    assert_eq!(structure["stats"]["nodes"].as_u64(), Some(stats.nodes as u64));
    assert_eq!(structure["stats"]["leaves"].as_u64(), Some(stats.leaves as u64));
    assert_eq!(structure["stats"]["triangles"].as_u64(), Some(586));
    assert_eq!(structure["stats"]["spheres"].as_u64(), Some(2));
    assert_eq!(s["limits"], serde_json::json!({"max_side": 4096, "max_spp": 65536}));
    assert_eq!(s["view"], Value::Null, "no view before the page asks for one");
}

#[test]
fn every_request_needs_the_token() {
    let server = start();
    let token = server.token().to_string();
    assert_eq!(token.len(), 32, "128 random bits in hex");
    assert!(server.url().ends_with(&format!("/?token={token}")));
    let wrong = format!("{}{}", &token[..31], if token.ends_with('0') { '1' } else { '0' });
    let refused = "a valid token is required (open the URL arbor view printed)";
    for &(method, path, body) in ROUTES {
        let no_token = request_with(server.addr(), method, path, &[], body);
        assert_eq!((no_token.status, no_token.error()), (403, refused.to_string()), "{method} {path} without a token");
        for bad in [wrong.as_str(), &token[..31], &format!("{token}0"), "", &token.to_uppercase()] {
            let header = request_with(server.addr(), method, path, &[("X-Arbor-Token", bad)], body);
            assert_eq!(header.status, 403, "{method} {path} with token header {bad:?}");
            let query = request_with(server.addr(), method, &with_query_token(path, bad), &[], body);
            assert_eq!(query.status, 403, "{method} {path} with token={bad:?}");
        }
        let near_miss = request_with(
            server.addr(),
            method,
            &with_query_token(path, "x").replace("token=x", &format!("xtoken={token}")),
            &[],
            body,
        );
        assert_eq!(near_miss.status, 403, "{method} {path}: only `token=` counts");
    }
    // Nothing refused had an effect: still no view, no rebuild.
    let scene = get(&server, "/api/scene").json();
    assert_eq!((&scene["view"], &scene["structure"]["kind"]), (&Value::Null, &Value::from("bvh-sah")));
    // Either form works (the event stream's `EventSource` can only use the query).
    for &(method, path, body) in ROUTES {
        if path == "/api/events" {
            continue; // a stream that does not end: `Events::open` checks the query form
        }
        let header = request_with(server.addr(), method, path, &[("X-Arbor-Token", &token)], body);
        assert_ne!(header.status, 403, "{method} {path} with the token in a header");
        let query = request_with(server.addr(), method, &with_query_token(path, &token), &[], body);
        assert_ne!(query.status, 403, "{method} {path} with the token in the query");
    }
    Events::open(&server);
    let r = request_with(server.addr(), "GET", &format!("/api/scene?a=1&token={token}&b=2"), &[], None);
    assert_eq!(r.status, 200, "the token anywhere in the query");
}

#[test]
fn the_host_must_name_this_server() {
    let server = start();
    let (addr, port, token) = (server.addr(), server.addr().port(), server.token());
    let ask = |host: Option<&str>| {
        let host = host.map(|h| format!("Host: {h}\r\n")).unwrap_or_default();
        let text = format!("GET /api/scene HTTP/1.1\r\n{host}X-Arbor-Token: {token}\r\nConnection: close\r\n\r\n");
        raw(addr, text.as_bytes()).expect("an answer")
    };
    for good in [format!("127.0.0.1:{port}"), format!("localhost:{port}"), format!("[::1]:{port}")] {
        assert_eq!(ask(Some(&good)).status, 200, "Host: {good}");
    }
    // A page on another name rebound to 127.0.0.1 sends its own name.
    for bad in
        [format!("evil.example:{port}"), "evil.example".into(), format!("127.0.0.1:{}", port ^ 1), "localhost".into()]
    {
        let r = ask(Some(&bad));
        assert_eq!((r.status, r.error()), (403, format!("host '{bad}' is not this server")), "Host: {bad}");
    }
    let r = ask(None);
    assert_eq!((r.status, r.error()), (403, "host '' is not this server".to_string()), "no Host");
    let http10 = raw(addr, format!("GET /api/scene?token={token} HTTP/1.0\r\n\r\n").as_bytes()).unwrap();
    assert_eq!(http10.status, 403, "HTTP/1.0 without a Host");
}

/// (method, path, body, the error message): each a 400 once a 64x48 view exists.
fn bad_requests() -> Vec<(&'static str, &'static str, &'static str, String)> {
    let accel_err = |s: &str| s.parse::<AccelKind>().unwrap_err().to_string();
    let depth_err = "boxes:x".parse::<arbor::integrator::DebugView>().unwrap_err().to_string();
    let mut k = arbor::accel::AccelConfig::from(AccelKind::KdTree);
    let unknown_param = k.set("nonsense", "1").unwrap_err().to_string();
    let out_of_range = k.set("empty-bonus", "2").unwrap_err().to_string();
    let side = "must be a whole number of pixels from 1 to 4096";
    let vector = "must be an array of 3 finite numbers";
    vec![
        ("GET", "/api/image?channel=depth", "", "'channel' must be render or overlay, not 'depth'".into()),
        ("GET", "/api/image?after=-1", "", "'after' must be a whole number, not '-1'".into()),
        ("GET", "/api/image?wait=soon", "", "'wait' must be a whole number, not 'soon'".into()),
        (
            "GET",
            "/api/image?wait=99999999999999999999",
            "",
            "'wait' must be a whole number, not '99999999999999999999'".into(),
        ),
        ("GET", "/api/inspect?y=1", "", "'x' is required".into()),
        ("GET", "/api/inspect?x=1", "", "'y' is required".into()),
        ("GET", "/api/inspect?x=1.5&y=1", "", "'x' must be a whole number, not '1.5'".into()),
        ("GET", "/api/inspect?x=64&y=0", "", "pixel (64, 0) is outside the 64x48 view".into()),
        ("GET", "/api/inspect?x=0&y=48", "", "pixel (0, 48) is outside the 64x48 view".into()),
        ("POST", "/api/view", "[0]", "the body must be a JSON object".into()),
        ("POST", "/api/view", r#"{"zoom": 2}"#, "unknown field \"zoom\"".into()),
        ("POST", "/api/view", r#"{"camera": 1}"#, "\"camera\" must be a camera index from 0 to 0".into()),
        ("POST", "/api/view", r#"{"camera": -1}"#, "\"camera\" must be a camera index from 0 to 0".into()),
        ("POST", "/api/view", r#"{"camera": "0"}"#, "\"camera\" must be a camera index from 0 to 0".into()),
        ("POST", "/api/view", r#"{"eye": [0, 0]}"#, format!("\"eye\" {vector}")),
        ("POST", "/api/view", r#"{"eye": [0, 0, 1e39]}"#, format!("\"eye\" {vector}")),
        ("POST", "/api/view", r#"{"up": [0, "1", 0]}"#, format!("\"up\" {vector}")),
        ("POST", "/api/view", r#"{"gaze": [0, 0, 0]}"#, "\"gaze\" and \"up\" must be non-zero and not parallel".into()),
        ("POST", "/api/view", r#"{"gaze": [0, 2, 0]}"#, "\"gaze\" and \"up\" must be non-zero and not parallel".into()),
        ("POST", "/api/view", r#"{"width": 0}"#, format!("\"width\" {side}")),
        ("POST", "/api/view", r#"{"width": 4097}"#, format!("\"width\" {side}")),
        ("POST", "/api/view", r#"{"height": 1.5}"#, format!("\"height\" {side}")),
        ("POST", "/api/view", r#"{"integrator": "photons"}"#, "\"integrator\" must be \"whitted\" or \"path\"".into()),
        ("POST", "/api/view", r#"{"overlay": "boxes:x"}"#, format!("\"overlay\": {depth_err}")),
        (
            "POST",
            "/api/view",
            r#"{"overlay": 3}"#,
            "\"overlay\" must be a string: none, boxes[:DEPTH], heatmap, primid or normal".into(),
        ),
        ("POST", "/api/view", r#"{"spp": 0}"#, "\"spp\" must be a whole number from 1 to 65536".into()),
        ("POST", "/api/view", r#"{"spp": 65537}"#, "\"spp\" must be a whole number from 1 to 65536".into()),
        ("POST", "/api/accel", "{}", "\"kind\" (a structure name) is required".into()),
        ("POST", "/api/accel", r#"{"kind": "quadtree"}"#, format!("\"kind\": {}", accel_err("quadtree"))),
        (
            "POST",
            "/api/accel",
            r#"{"kind": "kdtree", "params": [1]}"#,
            "\"params\" must be an object of key: value".into(),
        ),
        (
            "POST",
            "/api/accel",
            r#"{"kind": "kdtree", "params": {"depth": true}}"#,
            "parameter 'depth' must be a number or a word".into(),
        ),
        ("POST", "/api/accel", r#"{"kind": "kdtree", "params": {"nonsense": 1}}"#, unknown_param),
        ("POST", "/api/accel", r#"{"kind": "kdtree", "params": {"empty-bonus": 2}}"#, out_of_range),
        ("GET", "/api/compare?a=octree", "", "'b' (a structure name) is required".into()),
        ("GET", "/api/compare?b=octree", "", "'a' (a structure name) is required".into()),
        ("GET", "/api/compare?a=quadtree&b=octree", "", format!("'a': {}", accel_err("quadtree"))),
        ("GET", "/api/compare/image", "", "'kind' is required".into()),
    ]
}

#[test]
fn bad_parameters_are_400_with_a_message_and_change_nothing() {
    let server = start();
    let view = set_view(&server, r#"{"camera": 0, "width": 64, "height": 48, "spp": 1}"#);
    for (method, path, body, message) in bad_requests() {
        let r = request(&server, method, path, (method == "POST").then_some(body));
        assert_eq!((r.status, r.error()), (400, message), "{method} {path} {body}");
    }
    let scene = get(&server, "/api/scene").json();
    assert_eq!(scene["view"].as_u64(), Some(view), "no bad view was taken");
    assert_eq!(scene["structure"]["kind"], "bvh-sah", "no bad rebuild was started");
    assert_eq!(scene["structure"]["building"], false);
}

#[test]
fn malformed_and_oversized_bodies_are_4xx() {
    let server = start();
    let (addr, token) = (server.addr(), server.token());
    let post_raw = |headers: &str, body: &[u8]| {
        let mut text = format!(
            "POST /api/view HTTP/1.1\r\nHost: {addr}\r\nX-Arbor-Token: {token}\r\n{headers}Connection: close\r\n\r\n"
        )
        .into_bytes();
        text.extend_from_slice(body);
        raw(addr, &text).expect("an answer")
    };
    let sized = |body: &[u8]| post_raw(&format!("Content-Length: {}\r\n", body.len()), body);
    let not_json = |r: common::Reply| {
        assert_eq!(r.status, 400);
        assert!(r.error().starts_with("the body is not JSON: "), "{}", r.error());
    };
    not_json(sized(b""));
    not_json(sized(b"{\"camera\": 0"));
    not_json(sized(b"\xff\xfe{}"));
    not_json(sized(b"{\"camera\": 0} trailing"));
    not_json(sized(&[b'['; 5000])); // deeper than the JSON reader's recursion limit
    not_json(sized(b"camera=0"));
    // Too large: refused once 16 KiB have been read, whatever the length claims.
    let big = vec![b' '; 16 * 1024 + 1];
    for r in [sized(&big), post_raw("Content-Length: 99999999999\r\n", &big)] {
        assert_eq!(r.status, 413, "{:?}", String::from_utf8_lossy(&r.body));
        assert_eq!(r.error(), "the body is larger than 16384 bytes");
    }
    let chunked = |chunks: &[u8]| post_raw("Transfer-Encoding: chunked\r\n", chunks);
    // Bodies cut short: the server waits for the rest until the client closes its side.
    let head = format!("POST /api/view HTTP/1.1\r\nHost: {addr}\r\nX-Arbor-Token: {token}\r\nConnection: close\r\n");
    for framing in ["Content-Length: 40\r\n\r\n{}", "Transfer-Encoding: chunked\r\n\r\n4001\r\n{}"] {
        let r = raw_half_closed(addr, format!("{head}{framing}").as_bytes()).expect("an answer");
        assert_eq!(r.status, 400, "{framing:?}");
        assert!(r.error().starts_with("the body could not be read: "), "{}", r.error());
    }
    let mut many = Vec::new();
    for _ in 0..20 {
        many.extend_from_slice(b"400\r\n");
        many.extend_from_slice(&[b' '; 0x400]);
        many.extend_from_slice(b"\r\n");
    }
    many.extend_from_slice(b"0\r\n\r\n");
    assert_eq!(chunked(&many).status, 413, "20 KiB in chunks");
    assert_eq!(chunked(b"zz\r\nabc\r\n0\r\n\r\n").status, 400, "a broken chunk size");
    assert_eq!(post_raw("Content-Length: many\r\n", b"{}").status, 400);
    // A good body still works after all that.
    assert_eq!(sized(br#"{"camera": 0, "width": 8, "height": 8, "spp": 1}"#).status, 200);
}

#[test]
fn unknown_routes_are_404_and_wrong_methods_405() {
    let server = start();
    for path in [
        "/index.html",
        "/api",
        "/api/",
        "/api/scene/",
        "/api/images",
        "/api/compare/image/x",
        "/..%2f..%2fetc%2fpasswd",
        "/%zz",
    ] {
        let r = get(&server, path);
        assert_eq!((r.status, r.error()), (404, "no such page or endpoint".to_string()), "GET {path}");
    }
    for (method, path, allow) in [
        ("GET", "/api/view", "POST"),
        ("DELETE", "/api/scene", "GET,HEAD"),
        ("PUT", "/api/accel", "POST"),
        ("POST", "/api/image", "GET,HEAD"),
        ("POST", "/", "GET,HEAD"),
        ("PATCH", "/api/bench", "GET,HEAD,POST"),
    ] {
        let r = request(&server, method, path, None);
        assert_eq!(r.status, 405, "{method} {path}");
        assert_eq!(r.header("allow"), Some(allow), "{method} {path}");
        assert_eq!(r.error(), format!("{method} is not allowed on {path}"), "{method} {path}");
    }
    // Unknown paths and methods are behind the token like the rest.
    assert_eq!(request_with(server.addr(), "GET", "/nowhere", &[], None).status, 403);
    assert_eq!(request_with(server.addr(), "DELETE", "/api/scene", &[], None).status, 403);
}

#[test]
fn before_any_view_images_are_204_and_view_bound_requests_409() {
    let server = start();
    let r = get(&server, "/api/image?wait=0");
    assert_eq!((r.status, r.body.len()), (204, 0));
    assert_eq!(get(&server, "/api/image?channel=overlay&wait=1").status, 204);
    let no_view = "no view yet: POST /api/view first".to_string();
    for (method, path) in
        [("GET", "/api/inspect?x=0&y=0"), ("GET", "/api/compare?a=octree&b=kdtree"), ("POST", "/api/bench")]
    {
        let r = request(&server, method, path, (method == "POST").then_some(""));
        assert_eq!((r.status, r.error()), (409, no_view.clone()), "{method} {path}");
    }
    let r = get(&server, "/api/compare/image?kind=octree");
    assert_eq!((r.status, r.error()), (404, "no heatmap of 'octree': GET /api/compare first".to_string()));
    let bench = get(&server, "/api/bench").json();
    assert_eq!(bench, serde_json::json!({"state": "idle", "rows": []}));
}

#[test]
fn a_view_publishes_rgb_images_with_their_figures() {
    let server = start();
    let view = set_view(&server, r#"{"camera": 0, "width": 64, "height": 48, "spp": 2, "overlay": "heatmap"}"#);
    assert_eq!(view, 1);
    let r = image_of(&server, "render", view, 2);
    assert_eq!(r.header("content-type"), Some("application/octet-stream"));
    assert_eq!(r.header("cache-control"), Some("no-store"));
    assert_eq!((r.number("x-width"), r.number("x-height"), r.number("x-samples")), (64.0, 48.0, 2.0));
    assert_eq!(r.body.len(), 64 * 48 * 3);
    for h in ["x-render-ms", "x-mrays", "x-convert-ms"] {
        assert!(r.number(h) >= 0.0, "{h}");
    }
    assert!(r.header("x-heatmap-max").is_none(), "the render has no heatmap");
    let o = image_of(&server, "overlay", view, 1);
    assert_eq!((o.number("x-width"), o.number("x-height"), o.body.len()), (64.0, 48.0, 64 * 48 * 3));
    assert!(o.number("x-heatmap-max") > 0.0);
    // The last image is there at once for a late reader, and nothing newer comes: 204.
    let last = get(&server, "/api/image?after=0&wait=0");
    assert_eq!((last.status, last.number("x-seq")), (200, r.number("x-seq")));
    let none = get(&server, &format!("/api/image?after={}&wait=0", r.number("x-seq")));
    assert_eq!(none.status, 204);
    assert_eq!(get(&server, "/api/scene").json()["view"].as_u64(), Some(view));
}

#[test]
fn event_streams_are_limited_to_eight() {
    let server = start();
    let open: Vec<Events> = (0..8).map(|_| Events::open(&server)).collect();
    let r = get(&server, "/api/events");
    assert_eq!((r.status, r.error()), (503, "too many event streams open".to_string()));
    // The open streams all hear the same events.
    set_view(&server, r#"{"camera": 0, "width": 8, "height": 8, "spp": 1}"#);
    for mut e in open {
        let frame = e.until(|e| e["type"] == "frame");
        assert_eq!(frame.last().unwrap()["view"], 1);
    }
}
