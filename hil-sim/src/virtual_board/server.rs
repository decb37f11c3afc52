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

use model_core::protocol::frame::{encode, Deframer, MAX_ENCODED};

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

/// Hosts connected at once; a further connection is closed at once.
const CLIENTS: usize = 4;
/// A host that has sent nothing for this long is disconnected, s (its slot freed).
const CLIENT_IDLE: Duration = Duration::from_secs(30);

/// One connected host: its socket, its own deframer (its frames reach the board whole,
/// never interleaved with another host's bytes), when it last sent anything.
struct Client {
    stream: TcpStream,
    deframer: Deframer,
    heard: Instant,
}

/// The host side of the UART: the listener, the connected hosts, bytes in both directions.
/// Every host's whole frames go to the board's receive buffer, stamped with the wall-clock
/// time they arrived: the board takes them no earlier in its own time (a simulation that
/// runs behind real time sees a command as late as it really is); the board's bytes go to
/// every host (a shared line: each host matches the replies to its own commands).
struct Net {
    listener: TcpListener,
    clients: RefCell<Vec<Client>>,
    /// Host → board: frames waiting for their arrival time (µs since the start), then the
    /// UART's receive buffer; board → host.
    arriving: RefCell<VecDeque<(u64, Vec<u8>)>>,
    rx: RefCell<VecDeque<u8>>,
    tx: RefCell<Vec<u8>>,
    start: Instant,
}

impl Net {
    /// Accept new hosts; take what each sent; drop the silent and the gone.
    fn receive(&self) -> Result<(), ServeError> {
        let mut clients = self.clients.borrow_mut();
        while let Ok((s, peer)) = self.listener.accept() {
            if clients.len() >= CLIENTS {
                eprintln!("virtual board: {peer}: {CLIENTS} hosts connected already; closing the connection");
                continue;
            }
            s.set_nonblocking(true)?;
            s.set_nodelay(true)?;
            clients.push(Client { stream: s, deframer: Deframer::default(), heard: Instant::now() });
        }
        let now_us = self.start.elapsed().as_micros() as u64;
        let mut buf = [0u8; 4096];
        clients.retain_mut(|c| {
            let mut open = true;
            loop {
                match c.stream.read(&mut buf) {
                    Ok(0) => open = false,
                    Ok(n) => {
                        c.heard = Instant::now();
                        for &b in &buf[..n] {
                            if let Some(Ok(p)) = c.deframer.push(b) {
                                let mut e = [0u8; MAX_ENCODED];
                                let k = encode(p, &mut e);
                                self.arriving.borrow_mut().push_back((now_us, e[..k].to_vec()));
                            }
                        }
                        continue;
                    }
                    Err(e) if e.kind() == ErrorKind::Interrupted => continue,
                    Err(e) if e.kind() == ErrorKind::WouldBlock => {}
                    Err(_) => open = false,
                }
                break;
            }
            if open && c.heard.elapsed() > CLIENT_IDLE {
                eprintln!("virtual board: a host silent for {} s disconnected", CLIENT_IDLE.as_secs());
                open = false;
            }
            open
        });
        Ok(())
    }

    /// Frames that have arrived by board time `board_us` into the UART's receive buffer.
    fn deliver(&self, board_us: u64) {
        let mut arriving = self.arriving.borrow_mut();
        while arriving.front().is_some_and(|(at, _)| *at <= board_us) {
            if let Some((_, f)) = arriving.pop_front() {
                self.rx.borrow_mut().extend(f);
            }
        }
    }

    /// Send what the board wrote to every host; with none it is lost (the line is idle).
    fn send(&self) {
        let out = std::mem::take(&mut *self.tx.borrow_mut());
        if out.is_empty() {
            return;
        }
        self.clients.borrow_mut().retain_mut(|c| match c.stream.write(&out) {
            Ok(_) => true,
            // A host that does not read loses frames (a UART's full transmit buffer).
            Err(e) => e.kind() == ErrorKind::WouldBlock,
        });
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
    let start = Instant::now();
    let net = Net {
        listener,
        clients: RefCell::default(),
        arriving: RefCell::default(),
        rx: RefCell::default(),
        tx: RefCell::default(),
        start,
    };
    ready(net.listener.local_addr()?);
    let mut stall_us = opts.stall_tasks.map(|s| (s * 1e6).round() as u64);
    loop {
        run_boot(&clock, &flash, &mut board, &net, booted, stall_us.take())?;
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
    stall_us: Option<u64>,
) -> Result<(), ServeError> {
    let ctl = SimControl::new(running, damaged);
    let shared = Shared::new(running, damaged, crc);
    let (cfg, hz) = board.running();
    shared.set_limits(&cfg, hz);
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
        let due_us = net.start.elapsed().as_micros() as u64;
        let mut ran = 0;
        while board.time_us() <= due_us && ran < BURST {
            clock.set(board.time_us());
            net.deliver(board.time_us());
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
