//! The server's connections: a TCP listener that holds at most [`MAX_CONNECTIONS`] connections open
//! (the next one is accepted only once one closes; the operating system's backlog holds the rest), and
//! the loop that serves each over HTTP/1.1 with a deadline for its request headers ([`HEADER_TIMEOUT`]),
//! so that no number of clients, and no client that sends a request slowly or not at all, can make the
//! server hold unbounded sockets, buffers or tasks, or keep a slot forever.
//!
//! `axum::serve` sets no timer on hyper, so hyper's header deadline never applies there; this loop is
//! hyper's own connection builder with a timer, which axum's is too.

use std::io;
use std::pin::Pin;
use std::sync::Arc;
use std::task::{Context, Poll};

use tokio::io::{AsyncRead, AsyncWrite, ReadBuf};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::{OwnedSemaphorePermit, Semaphore};

/// Connections open at once.
pub const MAX_CONNECTIONS: usize = 32;
/// Time a connection has to send a request's headers, the first or the next one on a kept-alive
/// connection; past it the connection is closed and its slot given back.
pub const HEADER_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(10);

/// Serves `router` on `listener` until `stop` resolves. Each connection runs on a task of its own;
/// a connection's error (a reset, a header deadline passed) closes that connection only.
pub async fn serve(listener: TcpListener, router: axum::Router, stop: impl std::future::Future<Output = ()>) {
    let mut limited = Limited::new(listener);
    let mut http = hyper::server::conn::http1::Builder::new();
    http.timer(hyper_util::rt::TokioTimer::new()).header_read_timeout(HEADER_TIMEOUT);
    tokio::pin!(stop);
    loop {
        let connection = tokio::select! {
            _ = &mut stop => return,
            (connection, _) = axum::serve::Listener::accept(&mut limited) => connection,
        };
        let service = hyper_util::service::TowerToHyperService::new(router.clone());
        let serving = http.serve_connection(hyper_util::rt::TokioIo::new(connection), service);
        tokio::spawn(async move {
            let _ = serving.await;
        });
    }
}

/// [`TcpListener`] with a bound on open connections.
pub struct Limited {
    inner: TcpListener,
    slots: Arc<Semaphore>,
}

impl Limited {
    /// Wraps `inner`.
    pub fn new(inner: TcpListener) -> Limited {
        Limited { inner, slots: Arc::new(Semaphore::new(MAX_CONNECTIONS)) }
    }
}

/// A connection and its slot, given back when the connection is dropped.
pub struct Connection {
    stream: TcpStream,
    _slot: OwnedSemaphorePermit,
}

impl axum::serve::Listener for Limited {
    type Io = Connection;
    type Addr = std::net::SocketAddr;

    async fn accept(&mut self) -> (Connection, std::net::SocketAddr) {
        loop {
            // The semaphore is never closed, so acquiring only waits.
            let Ok(slot) = self.slots.clone().acquire_owned().await else { continue };
            match self.inner.accept().await {
                Ok((stream, addr)) => return (Connection { stream, _slot: slot }, addr),
                // Out of file descriptors and the like: wait a little rather than spin.
                Err(_) => tokio::time::sleep(std::time::Duration::from_millis(50)).await,
            }
        }
    }

    fn local_addr(&self) -> io::Result<std::net::SocketAddr> {
        self.inner.local_addr()
    }
}

impl AsyncRead for Connection {
    fn poll_read(mut self: Pin<&mut Self>, cx: &mut Context<'_>, buf: &mut ReadBuf<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.stream).poll_read(cx, buf)
    }
}

impl AsyncWrite for Connection {
    fn poll_write(mut self: Pin<&mut Self>, cx: &mut Context<'_>, buf: &[u8]) -> Poll<io::Result<usize>> {
        Pin::new(&mut self.stream).poll_write(cx, buf)
    }
    fn poll_flush(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.stream).poll_flush(cx)
    }
    fn poll_shutdown(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.stream).poll_shutdown(cx)
    }
}
