//! Random requests, seeded: methods, paths, queries, headers, framings and bodies drawn from pieces of
//! good requests and garbage, some with the token and this server's `Host` and some without, some cut
//! off mid-way. None may get a 5xx, and the server must answer a good request after all of them.

mod common;

use std::io::Write;
use std::net::TcpStream;

use common::*;

/// A small deterministic generator (xorshift64*), so that a failure replays.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn chance(&mut self, percent: u64) -> bool {
        self.next() % 100 < percent
    }
    fn pick<'a>(&mut self, items: &[&'a str]) -> &'a str {
        items[self.below(items.len())]
    }
    fn bytes(&mut self, n: usize) -> Vec<u8> {
        (0..n).map(|_| self.next() as u8).collect()
    }
}

const SEED: u64 = 0x5eed_a7b0_0f1e_1d00;
const REQUESTS: usize = 3000;

const METHODS: &[&str] = &[
    "GET", "GET", "GET", "POST", "POST", "PUT", "DELETE", "HEAD", "OPTIONS", "PATCH", "TRACE", "get", "G T", "BREW", "",
];
const PATHS: &[&str] = &[
    "/",
    "/api/scene",
    "/api/view",
    "/api/image",
    "/api/inspect",
    "/api/accel",
    "/api/compare",
    "/api/compare/image",
    "/api/bench",
    "/api/events",
    "/api",
    "/api/",
    "//api/scene",
    "/api/scene/..",
    "/../etc/passwd",
    "/%2e%2e/",
    "/%zz",
    "/api/scene%00",
    "*",
    "http://127.0.0.1/api/scene",
    "/\u{e9}t\u{e9}",
    "",
];
/// The API's routes and their methods (without the event stream, which does not end).
const ROUTES: &[(&str, &str)] = &[
    ("GET", "/api/scene"),
    ("POST", "/api/view"),
    ("POST", "/api/view"),
    ("GET", "/api/image"),
    ("GET", "/api/inspect"),
    ("GET", "/api/inspect"),
    ("POST", "/api/accel"),
    ("GET", "/api/compare"),
    ("GET", "/api/compare/image"),
    ("GET", "/api/bench"),
    ("POST", "/api/bench"),
];
const KEYS: &[&str] = &["channel", "after", "wait", "x", "y", "a", "b", "kind", "token", "", "x[]", "%zz", "y=1"];
const VALUES: &[&str] = &[
    "0",
    "1",
    "7",
    "15",
    "16",
    "-1",
    "1.5",
    "1e3",
    "x",
    "",
    "render",
    "overlay",
    "depth",
    "octree",
    "kdtree",
    "bvh-sah",
    "brute",
    "bvh-bottom-up",
    "quadtree",
    "%ff",
    "%00",
    "18446744073709551616",
    "\u{e9}",
    "a&b",
    "=",
];
/// Values for the JSON bodies: numbers in and out of range, wrong types, extremes.
const JSON_VALUES: &[&str] = &[
    "0",
    "1",
    "8",
    "16",
    "-1",
    "1.5",
    "4097",
    "1e300",
    "-0",
    "null",
    "true",
    "\"8\"",
    "\"\"",
    "[]",
    "{}",
    "[0, 0, 1]",
    "[0, 1, 0]",
    "[0, 0, 0]",
    "[1e39, 0, 0]",
    "[0, 0]",
    "[\"a\", 0, 0]",
    "\"whitted\"",
    "\"path\"",
    "\"boxes:2\"",
    "\"boxes:99\"",
    "\"heatmap\"",
    "\"primid\"",
    "\"normal\"",
    "\"none\"",
    "\"boxes:x\"",
    "\"octree\"",
    "\"kdtree\"",
    "{\"leaf\": 2}",
    "{\"depth\": \"auto\"}",
    "{\"leaf\": -3}",
    "{\"bins\": 1e9}",
    "{\"x\": {}}",
];
const FIELDS: &[&str] =
    &["camera", "eye", "gaze", "up", "width", "height", "integrator", "overlay", "spp", "kind", "params", "zoom", ""];

/// How a request ends.
#[derive(PartialEq)]
enum End {
    /// Whole as its framing says: the server answers it.
    Complete,
    /// Perhaps not (a body shorter than it claims, garbage): the client closes its side after it, as a
    /// client that gives up does, and the server answers or closes.
    Unsure,
    /// The client goes away half-way through.
    Abandoned,
}

/// A request drawn from `rng`, and how it ends.
fn request(rng: &mut Rng, server: &arbor_view::Server) -> (Vec<u8>, End) {
    if rng.chance(4) {
        let n = rng.below(600);
        return (rng.bytes(n), End::Unsure);
    }
    let mut end = End::Complete;
    let (addr, token) = (server.addr(), server.token());
    // Half the requests are well formed, to the API's routes with their methods, the token and this
    // server's host, so that the random queries and bodies reach the handlers; the others are wild.
    let wild = rng.chance(50);
    let (mut method, mut path) = (rng.pick(METHODS), rng.pick(PATHS).to_string());
    if !wild {
        let (m, p) = ROUTES[rng.below(ROUTES.len())];
        (method, path) = (m, p.to_string());
    }
    if wild && rng.chance(5) {
        path.push_str(&"a/".repeat(rng.below(5000)));
    }
    let mut query: Vec<String> =
        (0..rng.below(5)).map(|_| format!("{}={}", rng.pick(KEYS), rng.pick(VALUES))).collect();
    let good_token = !wild || rng.chance(75);
    // An event stream with the token is a stream that does not end; the limits on those are tested
    // by `api.rs`.
    let good_token = good_token && !path.contains("events");
    match (good_token, rng.below(3)) {
        (true, 0) => query.push(format!("token={token}")),
        (false, 0) => query.push(format!("token={}", rng.pick(VALUES))),
        _ => {}
    }
    if path.contains("image") {
        // A long poll answers when an image comes or after `wait`; keep it short.
        query.push(format!("wait={}", rng.below(3)));
    }
    if !query.is_empty() || rng.chance(5) {
        path = format!("{path}?{}", query.join("&"));
    }
    let version = if !wild || rng.chance(90) {
        "HTTP/1.1"
    } else {
        rng.pick(&["HTTP/1.0", "HTTP/2.0", "HTTP/9.9", "HTTP/1.1 x", ""])
    };
    let mut head = format!("{method} {path} {version}\r\n");
    if !wild || rng.chance(85) {
        head.push_str(&format!("Host: {addr}\r\n"));
    } else if rng.chance(50) {
        head.push_str(&format!("Host: {}\r\n", rng.pick(&["localhost", "evil.example", "", "127.0.0.1:1", "a b"])));
    }
    if good_token && (!wild || rng.chance(70)) {
        head.push_str(&format!("X-Arbor-Token: {token}\r\n"));
    } else if rng.chance(20) {
        head.push_str(&format!("X-Arbor-Token: {}\r\n", rng.pick(VALUES)));
    }
    for _ in 0..if wild { rng.below(3) } else { 0 } {
        let line = rng.pick(&[
            "Content-Type: text/plain",
            "Accept: */*",
            "Expect: 100-continue",
            "Upgrade: websocket",
            "X: \u{1}\u{2}",
            ": empty name",
            "no colon",
            "Transfer-Encoding: gzip, chunked",
        ]);
        if line.starts_with("Transfer-Encoding") {
            end = End::Unsure;
        }
        head.push_str(line);
        head.push_str("\r\n");
    }
    if wild && rng.chance(2) {
        head.push_str(&format!("X-Long: {}\r\n", "h".repeat(100_000)));
    }
    let body = body(rng);
    let chunked = wild && rng.chance(10);
    match if wild { rng.below(10) } else { 9 } {
        _ if chunked => head.push_str("Transfer-Encoding: chunked\r\n"),
        0 => {}
        1 => head
            .push_str(&format!("Content-Length: {}\r\n", rng.pick(&["-1", "x", "99999999999999999999", "1, 2", ""]))),
        2 => head.push_str(&format!("Content-Length: {}\r\nContent-Length: 0\r\n", body.len())),
        3 => {
            head.push_str(&format!("Content-Length: {}\r\n", body.len() + 1 + rng.below(40)));
            end = End::Unsure;
        }
        _ => head.push_str(&format!("Content-Length: {}\r\n", body.len())),
    }
    head.push_str("Connection: close\r\n\r\n");
    let mut bytes = head.into_bytes();
    if chunked {
        for piece in body.chunks(1 + rng.below(64)) {
            let size = if rng.chance(3) { "zz".to_string() } else { format!("{:x}", piece.len()) };
            bytes.extend_from_slice(format!("{size}\r\n").as_bytes());
            bytes.extend_from_slice(piece);
            bytes.extend_from_slice(b"\r\n");
        }
        if rng.chance(90) {
            bytes.extend_from_slice(b"0\r\n\r\n");
        } else {
            end = End::Unsure;
        }
    } else {
        bytes.extend_from_slice(&body);
    }
    if wild && rng.chance(5) {
        end = End::Abandoned;
    }
    (bytes, end)
}

/// A body: JSON objects of the API's fields with good and bad values, or broken JSON, or bytes.
fn body(rng: &mut Rng) -> Vec<u8> {
    match rng.below(10) {
        0 => Vec::new(),
        1 => {
            let n = rng.below(40_000);
            rng.bytes(n)
        }
        2 => "[".repeat(rng.below(10_000)).into_bytes(),
        _ => {
            let mut fields: Vec<String> =
                (0..rng.below(6)).map(|_| format!("\"{}\": {}", rng.pick(FIELDS), rng.pick(JSON_VALUES))).collect();
            // A view that would render at full size with many samples costs the test's time: views
            // drawn here are small when they are good.
            fields.push(format!(
                "\"width\": {}, \"height\": {}",
                rng.pick(&["8", "16", "0", "-1", "x"]),
                rng.pick(&["8", "12", "1e9"])
            ));
            let mut text = format!("{{{}}}", fields.join(", "));
            if rng.chance(10) {
                text.truncate(rng.below(text.len() + 1));
            }
            text.into_bytes()
        }
    }
}

#[test]
fn random_requests_never_get_a_5xx_nor_stop_the_server() {
    let server = start();
    set_view(&server, r#"{"camera": 0, "width": 16, "height": 16, "spp": 1}"#);
    let mut rng = Rng(SEED);
    let mut statuses = std::collections::BTreeMap::new();
    for i in 0..REQUESTS {
        let (bytes, end) = request(&mut rng, &server);
        let shown = String::from_utf8_lossy(&bytes[..bytes.len().min(300)]).into_owned();
        let status = match end {
            End::Abandoned => {
                let mut s = TcpStream::connect(server.addr()).unwrap();
                let _ = s.write_all(&bytes[..bytes.len() / 2]);
                continue;
            }
            End::Unsure => raw_half_closed(server.addr(), &bytes).map(|r| r.status),
            End::Complete => {
                let r = raw(server.addr(), &bytes);
                assert!(r.is_some(), "request {i} (seed {SEED:#x}) got no answer: {shown:?}");
                r.map(|r| r.status)
            }
        };
        *statuses.entry(status).or_insert(0) += 1;
        if let Some(s) = status {
            assert!(s < 500, "request {i} (seed {SEED:#x}) got {s}: {shown:?}");
        }
        if i % 100 == 99 {
            assert_eq!(get(&server, "/api/scene").status, 200, "the server answers after request {i}");
        }
    }
    eprintln!("statuses of {REQUESTS} random requests (None: closed without an answer): {statuses:?}");
    assert_eq!(get(&server, "/api/scene").status, 200);
    let view = set_view(&server, r#"{"camera": 0, "width": 8, "height": 8, "spp": 1}"#);
    assert_eq!(image_of(&server, "render", view, 1).body.len(), 8 * 8 * 3, "the server still renders");
    // Enough of the requests got through to the endpoints to mean something.
    let ok = statuses.iter().filter(|(s, _)| s.is_some_and(|s| s < 300)).map(|(_, n)| n).sum::<usize>();
    assert!(ok > REQUESTS / 10, "{statuses:?}");
}
