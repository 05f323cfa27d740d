//! `arbor view`: the live debugging display of a scene, in a web page served from the binary itself.
//!
//! A thin layer over the renderer. The page (`page/`, plain HTML, CSS and JavaScript embedded with
//! `include_str!`, no build step and no network) draws what a small HTTP/JSON API returns and holds no
//! rendering logic: every image is [`arbor::render::render_camera`]'s, every overlay one of the renderer's
//! debug views ([`arbor::integrator::DebugView`]), every inspected ray [`arbor::render::inspect_sample`]'s,
//! every benchmark figure [`arbor::bench`]'s. `docs/view.md` lists the endpoints.
//!
//! - [`frames`]: the progressive render of the current view on a thread of its own: a low-resolution
//!   first frame, then full-resolution passes of one sample each, averaged, until the view changes
//!   (which cancels the pass in flight) or its sample budget is spent.
//! - [`structures`]: the scene under the current structure, rebuilt in the background on request, and
//!   the other structures built for the comparisons (side-by-side heatmaps, the benchmark chart).
//! - [`api`]: the routes, and the checks every request passes (token, host, sizes); `server`: the
//!   [`Server`] that builds all this and serves the routes, with a bound on connections and a deadline
//!   for each request's headers (`listener`).
//!
//! The server is axum on a small tokio runtime: well kept, with Server-Sent Events for the page's
//! notifications, request-size and concurrency limits from tower, and no C dependencies. Long work (a
//! frame, a rebuild, a benchmark) runs on the renderer's rayon threads, never on the server's.
//!
//! Security follows Jupyter's local server: loopback unless `--listen` says otherwise, a random token in
//! the printed URL required on every request, a `Host` header that must name the server (against DNS
//! rebinding), and only the scene named on the command line is ever opened.

pub mod api;
mod bench;
pub mod frames;
mod inspect;
mod json;
mod listener;
mod server;
pub mod structures;

use std::net::SocketAddr;

use arbor::accel::AccelConfig;
use arbor::scene::SceneDesc;

pub use server::Server;

/// What `arbor view` serves.
pub struct ViewConfig {
    /// The scene, as read (and checked against the limits) by the command line.
    pub desc: SceneDesc,
    /// The structure to start with.
    pub accel: AccelConfig,
    /// Where to listen (port 0: any free port).
    pub addr: SocketAddr,
    /// The token every request must carry; `None` draws a random one.
    pub token: Option<String>,
}

/// A random token of 32 hex digits (128 bits from the operating system's generator).
pub fn random_token() -> std::io::Result<String> {
    let mut bytes = [0u8; 16];
    getrandom::fill(&mut bytes).map_err(|e| std::io::Error::other(e.to_string()))?;
    Ok(bytes.iter().map(|b| format!("{b:02x}")).collect())
}
