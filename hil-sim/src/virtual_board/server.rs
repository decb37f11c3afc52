//! The virtual board's socket and clock: one host connection at a time on a TCP port (the
//! board's UART), the firmware application's tasks (`firmware::application`: serial link,
//! supervisor, telemetry, watchdog) run by a single-threaded executor in simulated time,
//! the control samples paced to the wall clock (simulated real time: it never runs ahead;
//! it falls behind only if the host machine is too slow). Before every sample the clock
//! is set to that sample's time and the tasks are polled, so a task waiting until time `t`
//! runs before the first sample at or after `t`; what they leave for the control interrupt
//! applies from that sample on. A watchdog that expires (a task stalled) resets the board:
//! the tasks and the controller start again from flash, the plant keeps running.

use std::cell::{Cell, RefCell};
use std::collections::VecDeque;
use std::future::Future;
use std::io::{ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::pin::{pin, Pin};
use std::task::{Context, Poll, Waker};
use std::time::{Duration, Instant};

use embassy_futures::select::select4;
use firmware::application::{self, store, App, Clock, Shared};
use firmware::bringup::ResetCause;
use thiserror::Error;

use super::board::{Journal, VirtualBoard};
use super::ports::{expired, PipeRx, PipeTx, SimClock, SimControl, SimFlash, SimWatchdog, Stderr};
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
    /// From this simulated time on, s, the tasks stop being polled (a task that never
    /// yields): the watchdog resets the board, which then runs normally.
    pub stall_tasks: Option<f64>,
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

/// Poll `f` once (the executor: every task is polled before every sample, so no waker).
fn poll_once<F: Future>(f: Pin<&mut F>) -> Option<F::Output> {
    match f.poll(&mut Context::from_waker(Waker::noop())) {
        Poll::Ready(o) => Some(o),
        Poll::Pending => None,
    }
}

/// The host side of the UART: the listener, the connected host, bytes in both directions.
struct Net {
    listener: TcpListener,
    client: RefCell<Option<TcpStream>>,
    /// Host → board (the UART's receive buffer) and board → host.
    rx: RefCell<VecDeque<u8>>,
    tx: RefCell<Vec<u8>>,
}

impl Net {
    /// Accept a host if none is connected; move what it sent into `rx`.
    fn receive(&self) -> Result<(), ServeError> {
        let mut client = self.client.borrow_mut();
        if client.is_none() {
            if let Ok((s, _)) = self.listener.accept() {
                s.set_nonblocking(true)?;
                s.set_nodelay(true)?;
                *client = Some(s);
            }
        }
        let mut buf = [0u8; 4096];
        if let Some(s) = client.as_mut() {
            match s.read(&mut buf) {
                Ok(0) => *client = None,
                Ok(n) => self.rx.borrow_mut().extend(&buf[..n]),
                Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::Interrupted) => {}
                Err(_) => *client = None,
            }
        }
        Ok(())
    }

    /// Send what the board wrote; with no host it is lost (the UART's line is idle).
    fn send(&self) {
        let out = std::mem::take(&mut *self.tx.borrow_mut());
        let mut client = self.client.borrow_mut();
        if let (Some(s), false) = (client.as_mut(), out.is_empty()) {
            // A host that does not read loses frames (a UART's full transmit buffer).
            if let Err(e) = s.write(&out) {
                if e.kind() != ErrorKind::WouldBlock {
                    *client = None;
                }
            }
        }
    }
}

/// Serve until the process ends; `ready` gets the address once listening.
pub fn serve(opts: ServeOptions, ready: &mut dyn FnMut(SocketAddr)) -> Result<(), ServeError> {
    let addr = opts.listen.strip_prefix("tcp:").ok_or_else(|| ServeError::BadListen(opts.listen.clone()))?;
    let listener = TcpListener::bind(addr).map_err(|source| ServeError::Bind { addr: addr.to_owned(), source })?;
    listener.set_nonblocking(true)?;
    let clock = SimClock::default();
    let flash = SimFlash::new(&clock);
    let boot = store::load(&flash, &Stderr).map_err(ServeError::Page)?;
    let mut booted = (boot.running, boot.damaged, boot.crc);
    let mut board = VirtualBoard::new(&opts.clutch, opts.seed, opts.fault, opts.journal, boot.lp, boot.cfg);
    let net = Net { listener, client: RefCell::new(None), rx: RefCell::default(), tx: RefCell::default() };
    ready(net.listener.local_addr()?);
    let start = Instant::now();
    let mut stall_us = opts.stall_tasks.map(|s| (s * 1e6).round() as u64);
    loop {
        run_boot(&clock, &flash, &mut board, &net, booted, start, stall_us.take())?;
        eprintln!(
            "virtual board: watchdog reset at {:.4} s; starting again, reset cause {:?}",
            clock.now_us() as f64 * 1e-6,
            ResetCause::IndependentWatchdog
        );
        let boot = store::load(&flash, &Stderr).map_err(ServeError::Page)?;
        booted = (boot.running, boot.damaged, boot.crc);
        board.reboot(boot.lp, boot.cfg);
    }
}

/// One boot of the application: runs until the watchdog expires (tasks stalled from
/// `stall_us` on, µs, when given).
fn run_boot(
    clock: &SimClock,
    flash: &SimFlash<'_>,
    board: &mut VirtualBoard,
    net: &Net,
    (running, damaged, crc): (Option<(firmware::slots::Slot, u32)>, bool, u32),
    start: Instant,
    stall_us: Option<u64>,
) -> Result<(), ServeError> {
    let ctl = SimControl::new(running, damaged);
    let shared = Shared::new(running, damaged, crc);
    let last_pet = Cell::new(None);
    let mut wd = SimWatchdog::new(clock, &last_pet);
    let app = App { clock, flash, ctl: &ctl, events: &Stderr, shared: &shared };
    let (rx, tx) = (PipeRx(&net.rx), PipeTx(&net.tx));
    let mut tasks = pin!(select4(
        application::serial::run(app, rx, tx),
        application::supervisor::run(app),
        application::telemetry::run(app),
        application::watchdog::run(app, &mut wd),
    ));
    loop {
        net.receive()?;
        // Simulated real time: every sample whose time has come on the wall clock.
        let due_us = start.elapsed().as_micros() as u64;
        let mut ran = 0;
        while board.time_us() <= due_us && ran < BURST {
            clock.set(board.time_us());
            // The tasks never end (`-> !`); polled before every sample.
            if stall_us.is_none_or(|t| clock.now_us() < t) {
                let _ = poll_once(tasks.as_mut());
            }
            if expired(last_pet.get(), clock.now_us()) {
                net.send();
                return Ok(());
            }
            board.sample(&ctl);
            ran += 1;
        }
        net.send();
        if ran == 0 {
            std::thread::sleep(Duration::from_micros(100));
        }
    }
}
