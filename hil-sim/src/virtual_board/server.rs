//! The virtual board's socket and clock: one host connection at a time on a TCP port, the
//! control loop paced to the wall clock (simulated real time: it never runs ahead; it
//! falls behind only if the host machine is too slow), frames read between samples and
//! applied from the next sample on.

use std::io::{ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::time::{Duration, Instant};

use model_core::protocol::frame::Deframer;
use thiserror::Error;

use super::board::{Journal, VirtualBoard};
use crate::closed_loop::Schedule;
use crate::sim::plant::ClutchParams;

/// What the virtual board runs.
pub struct ServeOptions {
    /// `tcp:HOST:PORT` (port 0: any free port).
    pub listen: String,
    pub clutch: ClutchParams,
    /// Noise seed of the plant.
    pub seed: u64,
    pub fault: Option<Schedule>,
    pub journal: Journal,
}

#[derive(Debug, Error)]
pub enum ServeError {
    #[error("--listen `{0}`: expected tcp:HOST:PORT (e.g. tcp:127.0.0.1:7000)")]
    BadListen(String),
    #[error("{addr}: cannot listen: {source}")]
    Bind { addr: String, source: std::io::Error },
    #[error("virtual board: {0}")]
    Io(#[from] std::io::Error),
    #[error("virtual board: the compiled-in configuration is refused: {0}")]
    Page(model_core::control::PageError),
}

/// Samples run at most between two reads of the socket (0.5 ms at 20 kHz).
const BURST: usize = 10;

/// Serve until the process ends; `ready` gets the address once listening.
pub fn serve(opts: ServeOptions, ready: &mut dyn FnMut(SocketAddr)) -> Result<(), ServeError> {
    let addr = opts.listen.strip_prefix("tcp:").ok_or_else(|| ServeError::BadListen(opts.listen.clone()))?;
    let listener = TcpListener::bind(addr).map_err(|source| ServeError::Bind { addr: addr.to_owned(), source })?;
    listener.set_nonblocking(true)?;
    let mut board = VirtualBoard::new(&opts.clutch, opts.seed, opts.fault, opts.journal).map_err(ServeError::Page)?;
    ready(listener.local_addr()?);
    let hz = board.control_hz();
    let start = Instant::now();
    let mut client: Option<(TcpStream, Deframer)> = None;
    let mut buf = [0u8; 4096];
    loop {
        if client.is_none() {
            if let Ok((s, _)) = listener.accept() {
                s.set_nonblocking(true)?;
                s.set_nodelay(true)?;
                client = Some((s, Deframer::default()));
            }
        }
        let mut out = Vec::new();
        if let Some((s, d)) = client.as_mut() {
            match s.read(&mut buf) {
                Ok(0) => client = None,
                Ok(n) => {
                    for &b in &buf[..n] {
                        if let Some(Ok(p)) = d.push(b) {
                            let p = p.to_vec();
                            out.extend(board.frame(&p));
                        }
                    }
                }
                Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::Interrupted) => {}
                Err(_) => client = None,
            }
        }
        let due = (start.elapsed().as_secs_f64() * hz) as usize;
        let mut ran = 0;
        while board.samples() < due && ran < BURST {
            if let Some(f) = board.sample() {
                out.extend(f);
            }
            ran += 1;
        }
        if let (Some((s, _)), false) = (client.as_mut(), out.is_empty()) {
            // A host that does not read loses frames (a UART's full transmit buffer).
            if let Err(e) = s.write(&out) {
                if e.kind() != ErrorKind::WouldBlock {
                    client = None;
                }
            }
        }
        if ran == 0 {
            std::thread::sleep(Duration::from_micros(100));
        }
    }
}
