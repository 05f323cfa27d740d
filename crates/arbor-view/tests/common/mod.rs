//! Fixtures shared by the API tests: a server on the example Cornell box, started in this process on
//! `127.0.0.1:0`; a raw HTTP/1.1 client over [`TcpStream`] (raw, so that the tests can send what no
//! well-behaved client would: wrong `Host` headers, broken framing, garbage); a reader of the event
//! stream; and a way to hold every rayon thread, which stops the renderer's work (frames, builds,
//! heatmaps, benchmarks) at a known point without any timing.
#![allow(dead_code)]

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::PathBuf;
use std::sync::mpsc;
use std::sync::{Arc, Condvar, Mutex};
use std::time::Duration;

use arbor::accel::{AccelConfig, AccelKind};
use arbor::scene::{Scene, SceneDesc};
use arbor_view::{Server, ViewConfig};
use serde_json::Value;

/// How long a read waits before the test gives up: a hang guard, far beyond any expected answer.
pub const HANG_GUARD: Duration = Duration::from_secs(120);

/// A file of the repository's `examples/`.
pub fn example(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name)
}

/// The example Cornell box's description (meshes inline, two spheres).
pub fn cornell() -> SceneDesc {
    arbor::scene::load_desc(&example("cornell_box.xml")).expect("the example scene loads")
}

/// The example scene built under `kind` with its default parameters, as the server builds it.
pub fn built(kind: AccelKind) -> Scene {
    Scene::build(cornell(), &AccelConfig::from(kind), None).expect("the example scene builds")
}

/// A server on the example Cornell box with a BVH (SAH), on any free loopback port.
pub fn start() -> Server {
    start_with(cornell())
}

/// A server on `desc`, starting with a BVH (SAH).
pub fn start_with(desc: SceneDesc) -> Server {
    let addr: SocketAddr = "127.0.0.1:0".parse().unwrap();
    let config = ViewConfig { desc, accel: AccelConfig::from(AccelKind::BvhSah), addr, token: None };
    let server = Server::start(config).expect("the server starts");
    assert_ne!(server.addr().port(), 0, "the server says which port it got");
    server
}

/// An answer: status, headers (names in lower case) and the body, de-chunked.
#[derive(Debug)]
pub struct Reply {
    pub status: u16,
    pub headers: Vec<(String, String)>,
    pub body: Vec<u8>,
}

impl Reply {
    /// The value of header `name` (lower case).
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers.iter().find(|(k, _)| k == name).map(|(_, v)| v.as_str())
    }

    /// A number from header `name`.
    pub fn number(&self, name: &str) -> f64 {
        let v = self.header(name).unwrap_or_else(|| panic!("no header {name} in {self:?}"));
        v.parse().unwrap_or_else(|_| panic!("header {name} is not a number: {v}"))
    }

    /// The body as JSON.
    pub fn json(&self) -> Value {
        serde_json::from_slice(&self.body)
            .unwrap_or_else(|e| panic!("the body is not JSON ({e}): {}", String::from_utf8_lossy(&self.body)))
    }

    /// The message of an error answer, checking that it is one: `{"error": "..."}` as JSON.
    pub fn error(&self) -> String {
        assert_eq!(self.header("content-type"), Some("application/json"), "an error is JSON: {self:?}");
        self.json()["error"].as_str().unwrap_or_else(|| panic!("no \"error\" in {self:?}")).to_string()
    }
}

/// Sends `bytes` as they are on a new connection and reads until the server closes it; `None` when it
/// closed without answering.
pub fn raw(addr: SocketAddr, bytes: &[u8]) -> Option<Reply> {
    send(addr, bytes, false)
}

/// As [`raw`], then closes the writing side: the end of a request cut short (the server would wait for
/// its rest). The server drops a request whose client closed this way, complete or not.
pub fn raw_half_closed(addr: SocketAddr, bytes: &[u8]) -> Option<Reply> {
    send(addr, bytes, true)
}

fn send(addr: SocketAddr, bytes: &[u8], half_close: bool) -> Option<Reply> {
    let mut s = TcpStream::connect(addr).expect("connects");
    s.set_read_timeout(Some(HANG_GUARD)).unwrap();
    // The server may answer and close before it has read everything (a body it refuses): then the
    // rest of the write fails, and the answer is still there to read.
    let _ = s.write_all(bytes);
    if half_close {
        let _ = s.shutdown(std::net::Shutdown::Write);
    }
    let mut out = Vec::new();
    match s.read_to_end(&mut out) {
        Ok(_) => {}
        Err(e) if e.kind() == std::io::ErrorKind::ConnectionReset && !out.is_empty() => {}
        Err(e) if e.kind() == std::io::ErrorKind::ConnectionReset => return None,
        Err(e) => panic!("no answer within the hang guard ({e}) to {:?}", String::from_utf8_lossy(bytes)),
    }
    if out.is_empty() {
        return None;
    }
    Some(parse(&out))
}

/// An HTTP/1.1 response read whole.
pub fn parse(out: &[u8]) -> Reply {
    let end = out.windows(4).position(|w| w == b"\r\n\r\n").expect("a complete head");
    let head = String::from_utf8_lossy(&out[..end]);
    let mut lines = head.split("\r\n");
    let status_line = lines.next().unwrap();
    let status = status_line.split(' ').nth(1).and_then(|s| s.parse().ok()).expect("a status code");
    let headers: Vec<(String, String)> = lines
        .filter_map(|l| l.split_once(':'))
        .map(|(k, v)| (k.trim().to_ascii_lowercase(), v.trim().to_string()))
        .collect();
    let rest = &out[end + 4..];
    let chunked = headers.iter().any(|(k, v)| k == "transfer-encoding" && v.contains("chunked"));
    let body = if chunked { dechunk(rest) } else { rest.to_vec() };
    Reply { status, headers, body }
}

/// The payload of a chunked body.
fn dechunk(mut data: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    loop {
        let Some(eol) = data.windows(2).position(|w| w == b"\r\n") else { return out };
        let size = usize::from_str_radix(String::from_utf8_lossy(&data[..eol]).trim(), 16).unwrap_or(0);
        if size == 0 || data.len() < eol + 2 + size {
            return out;
        }
        out.extend_from_slice(&data[eol + 2..eol + 2 + size]);
        data = &data[(eol + 4 + size).min(data.len())..];
    }
}

/// A request as the page makes it: the server's host, its token in a header, a JSON body if any.
pub fn request(server: &Server, method: &str, path: &str, body: Option<&str>) -> Reply {
    let headers = [("X-Arbor-Token", server.token())];
    request_with(server.addr(), method, path, &headers, body)
}

/// A request with the server's `Host` and the given other headers.
pub fn request_with(addr: SocketAddr, method: &str, path: &str, headers: &[(&str, &str)], body: Option<&str>) -> Reply {
    let mut text = format!("{method} {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n");
    for (k, v) in headers {
        text.push_str(&format!("{k}: {v}\r\n"));
    }
    if let Some(b) = body {
        text.push_str(&format!("Content-Type: application/json\r\nContent-Length: {}\r\n\r\n{b}", b.len()));
    } else {
        text.push_str("\r\n");
    }
    raw(addr, text.as_bytes()).unwrap_or_else(|| panic!("no answer to {method} {path}"))
}

pub fn get(server: &Server, path: &str) -> Reply {
    request(server, "GET", path, None)
}

pub fn post(server: &Server, path: &str, body: &str) -> Reply {
    request(server, "POST", path, Some(body))
}

/// POSTs a view and returns its number.
pub fn set_view(server: &Server, body: &str) -> u64 {
    let r = post(server, "/api/view", body);
    assert_eq!(r.status, 200, "view {body}: {}", String::from_utf8_lossy(&r.body));
    r.json()["view"].as_u64().expect("a view number")
}

/// The image of `channel` newer than `after`, waiting for it (the hang guard bounds the wait).
pub fn image_after(server: &Server, channel: &str, after: u64) -> Reply {
    loop {
        let r = get(server, &format!("/api/image?channel={channel}&after={after}&wait=20000"));
        match r.status {
            200 => return r,
            204 => continue,
            s => panic!("image: {s} {}", String::from_utf8_lossy(&r.body)),
        }
    }
}

/// The first image of view `view` on `channel` with at least `samples` samples.
pub fn image_of(server: &Server, channel: &str, view: u64, samples: u32) -> Reply {
    let mut after = 0;
    loop {
        let r = image_after(server, channel, after);
        after = r.number("x-seq") as u64;
        let v = r.number("x-view") as u64;
        if v == view && r.number("x-samples") as u32 >= samples {
            return r;
        }
        assert!(v <= view, "an image of view {v} after view {view} was asked for");
    }
}

/// The server's event stream, read as it comes.
pub struct Events {
    reader: BufReader<TcpStream>,
    text: String,
}

impl Events {
    /// Opens the stream (with the token in the query, as the page's `EventSource` does) and reads its
    /// `hello`.
    pub fn open(server: &Server) -> Events {
        let mut s = TcpStream::connect(server.addr()).unwrap();
        s.set_read_timeout(Some(HANG_GUARD)).unwrap();
        let addr = server.addr();
        write!(s, "GET /api/events?token={} HTTP/1.1\r\nHost: {addr}\r\n\r\n", server.token()).unwrap();
        let mut reader = BufReader::new(s);
        let mut line = String::new();
        reader.read_line(&mut line).unwrap();
        assert!(line.starts_with("HTTP/1.1 200"), "events: {line}");
        loop {
            line.clear();
            reader.read_line(&mut line).expect("the stream's head");
            if line == "\r\n" {
                break;
            }
        }
        let mut events = Events { reader, text: String::new() };
        assert_eq!(events.next()["type"], "hello");
        events
    }

    /// The next event.
    pub fn next(&mut self) -> Value {
        loop {
            if let Some(end) = self.text.find("\n\n") {
                let event: String = self.text.drain(..end + 2).collect();
                let data: String = event.lines().filter_map(|l| l.strip_prefix("data:")).map(str::trim).collect();
                if data.is_empty() {
                    continue; // a keep-alive comment
                }
                return serde_json::from_str(&data).unwrap_or_else(|e| panic!("event {data:?}: {e}"));
            }
            // One chunk: its size in hex, then the bytes.
            let mut size = String::new();
            self.reader.read_line(&mut size).expect("an event within the hang guard");
            let n = usize::from_str_radix(size.trim(), 16).unwrap_or_else(|_| panic!("chunk size {size:?}"));
            assert!(n > 0, "the event stream ended");
            let mut chunk = vec![0; n + 2];
            self.reader.read_exact(&mut chunk).unwrap();
            self.text.push_str(&String::from_utf8_lossy(&chunk[..n]));
        }
    }

    /// Events up to and including the first for which `done` holds (within the hang guard: events
    /// that keep coming without it fail the test too).
    pub fn until(&mut self, done: impl Fn(&Value) -> bool) -> Vec<Value> {
        let mut seen = Vec::new();
        let start = std::time::Instant::now();
        loop {
            assert!(start.elapsed() < HANG_GUARD, "the awaited event did not come within the hang guard");
            let e = self.next();
            let stop = done(&e);
            seen.push(e);
            if stop {
                return seen;
            }
        }
    }

    /// [`Events::until`] view `view`'s frame of `samples` samples.
    pub fn until_frame(&mut self, view: u64, samples: u64) -> Vec<Value> {
        self.until(|e| e["type"] == "frame" && e["view"] == view && e["samples"] == samples)
    }
}

/// Every thread of rayon's global pool held until this is dropped: the renderer's parallel work (a
/// frame's tiles, a structure's build, a heatmap, a benchmark's traces) waits at its first parallel
/// step, so a test can make requests while that work is known to be in progress.
pub struct PoolHold {
    gate: Arc<(Mutex<bool>, Condvar)>,
    // Two holds at once could each get some threads and wait forever for the rest.
    _one_at_a_time: std::sync::MutexGuard<'static, ()>,
}

impl PoolHold {
    /// Holds every thread; returns once each one is held.
    pub fn new() -> PoolHold {
        static ONE: Mutex<()> = Mutex::new(());
        let one_at_a_time = ONE.lock().unwrap_or_else(|e| e.into_inner());
        let gate = Arc::new((Mutex::new(false), Condvar::new()));
        let (started, held) = mpsc::channel();
        let g = gate.clone();
        rayon::spawn_broadcast(move |_| {
            started.send(()).unwrap();
            let (open, cv) = &*g;
            let mut open = open.lock().unwrap();
            while !*open {
                open = cv.wait(open).unwrap();
            }
        });
        for _ in 0..rayon::current_num_threads() {
            held.recv_timeout(HANG_GUARD).expect("every rayon thread is held");
        }
        PoolHold { gate, _one_at_a_time: one_at_a_time }
    }
}

impl Drop for PoolHold {
    fn drop(&mut self) {
        let (open, cv) = &*self.gate;
        *open.lock().unwrap() = true;
        cv.notify_all();
    }
}
