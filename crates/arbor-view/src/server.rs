//! The server's life: the scene built, the frame worker started, the socket bound, and the routes
//! ([`crate::api`]) served on a small tokio runtime of their own ([`crate::listener::serve`]) until the
//! [`Server`] is dropped.

use std::collections::HashMap;
use std::net::SocketAddr;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use tokio::sync::{broadcast, Semaphore};

use crate::api::{routes, App, HEAVY, STREAMS};
use crate::bench::Bench;
use crate::frames::Frames;
use crate::structures::Structures;
use crate::ViewConfig;

/// A running `arbor view` server.
pub struct Server {
    addr: SocketAddr,
    token: String,
    runtime: Option<tokio::runtime::Runtime>,
    stop: Option<tokio::sync::oneshot::Sender<()>>,
}

impl Server {
    /// Builds the scene, binds `config.addr` and starts serving in the background.
    pub fn start(config: ViewConfig) -> Result<Server, arbor::Error> {
        let token = match config.token {
            Some(t) => t,
            None => crate::random_token().map_err(|e| arbor::Error::Invalid(format!("cannot draw a token: {e}")))?,
        };
        let (events, _) = broadcast::channel(256);
        let structures = Arc::new(Structures::new(config.desc, config.accel, events.clone())?);
        let frames = Frames::start(structures.clone(), events.clone());
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(2)
            .max_blocking_threads(HEAVY + 2)
            .enable_all()
            .build()
            .map_err(|e| arbor::Error::Invalid(format!("cannot start the server: {e}")))?;
        let listener = runtime
            .block_on(tokio::net::TcpListener::bind(config.addr))
            .map_err(|e| arbor::Error::Invalid(format!("cannot listen on {}: {e}", config.addr)))?;
        let addr = listener.local_addr().map_err(|e| arbor::Error::Invalid(e.to_string()))?;
        let hosts = allowed_hosts(addr);
        let app = Arc::new(App {
            structures,
            frames,
            bench: Arc::new(Bench::default()),
            events,
            token: token.clone(),
            hosts,
            heavy: Arc::new(Semaphore::new(HEAVY)),
            streams: Arc::new(Semaphore::new(STREAMS)),
            compared: Mutex::new(HashMap::new()),
        });
        let router = routes(app);
        let (stop, stopped) = tokio::sync::oneshot::channel::<()>();
        runtime.spawn(crate::listener::serve(listener, router, async move {
            let _ = stopped.await;
        }));
        Ok(Server { addr, token, runtime: Some(runtime), stop: Some(stop) })
    }

    /// The address it listens on.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// The token every request needs.
    pub fn token(&self) -> &str {
        &self.token
    }

    /// The URL to open: the page, with its token.
    pub fn url(&self) -> String {
        format!("http://{}/?token={}", self.addr, self.token)
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        if let Some(stop) = self.stop.take() {
            let _ = stop.send(());
        }
        if let Some(rt) = self.runtime.take() {
            rt.shutdown_timeout(Duration::from_secs(1));
        }
    }
}

/// The `Host` values a request may carry: the address served, and for loopback `localhost` too.
fn allowed_hosts(addr: SocketAddr) -> Vec<String> {
    let port = addr.port();
    let mut hosts = vec![addr.to_string()];
    if addr.ip().is_loopback() {
        hosts.extend([format!("localhost:{port}"), format!("127.0.0.1:{port}"), format!("[::1]:{port}")]);
    }
    hosts
}
