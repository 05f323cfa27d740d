//! Connections that never finish a request: the server holds at most 32 connections, so clients that
//! open them and send half a request (slowloris) would lock everyone out if the server waited for them
//! forever. Each connection has 10 s to send its headers (`listener::HEADER_TIMEOUT`), and a body as long
//! again after them.

mod common;

use std::io::{Read, Write};
use std::net::TcpStream;

use common::{get, start, HANG_GUARD};

#[test]
fn clients_that_never_finish_their_headers_do_not_lock_the_server_out() {
    let server = start();
    let half = format!("GET /api/scene HTTP/1.1\r\nHost: {}\r\nX-Arbor-Token: {}\r\n", server.addr(), server.token());
    // Every slot taken by a connection that sends part of its headers and then nothing.
    let mut stalled: Vec<TcpStream> = (0..32)
        .map(|_| {
            let mut s = TcpStream::connect(server.addr()).expect("connects");
            s.write_all(half.as_bytes()).unwrap();
            s.set_read_timeout(Some(HANG_GUARD)).unwrap();
            s
        })
        .collect();
    // A well-formed request still gets its answer: the stalled connections are closed at their deadline
    // and their slots given back (without the deadline, this waits forever, caught by the hang guard).
    let reply = get(&server, "/api/scene");
    assert_eq!(reply.status, 200, "{}", reply.error());
    for s in &mut stalled {
        let mut rest = Vec::new();
        // Closed by the server: the read ends (at end of stream, or reset) rather than at the hang guard.
        match s.read_to_end(&mut rest) {
            Ok(_) => {}
            Err(e) => assert_ne!(e.kind(), std::io::ErrorKind::WouldBlock, "a stalled connection is still open"),
        }
    }
}

#[test]
fn clients_that_never_finish_their_bodies_get_408_and_do_not_lock_the_server_out() {
    let server = start();
    let (addr, token) = (server.addr(), server.token());
    let half = format!(
        "POST /api/view HTTP/1.1\r\nHost: {addr}\r\nX-Arbor-Token: {token}\r\nContent-Length: 100\r\n\r\n{{\"camera\""
    );
    let mut stalled: Vec<TcpStream> = (0..32)
        .map(|_| {
            let mut s = TcpStream::connect(addr).expect("connects");
            s.write_all(half.as_bytes()).unwrap();
            s.set_read_timeout(Some(HANG_GUARD)).unwrap();
            s
        })
        .collect();
    // Without the body's deadline every slot stays taken and this waits for the hang guard.
    let reply = get(&server, "/api/scene");
    assert_eq!(reply.status, 200, "{}", reply.error());
    let mut answer = Vec::new();
    let _ = stalled[0].read_to_end(&mut answer);
    let answer = String::from_utf8_lossy(&answer);
    assert!(answer.starts_with("HTTP/1.1 408"), "a stalled body is answered 408: {answer}");
    assert!(answer.contains("the body did not arrive within 10 s"), "{answer}");
}
