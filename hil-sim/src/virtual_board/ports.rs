//! The firmware application's ports ([`firmware::application::ports`]) on the host: a
//! simulated clock the control samples advance, the two flash slots with the G474's erase
//! and program times, the control interrupt's shared state as cells, a modelled independent
//! watchdog, the log on stderr, and the byte link as two in-memory pipes the server fills
//! from and drains to the TCP socket.

use std::cell::{Cell, RefCell};
use std::collections::VecDeque;
use std::convert::Infallible;
use std::future::{poll_fn, Future};
use std::task::Poll;

use firmware::application::{
    store, Clock, ControlPort, EccError, Event, Events, FlashFault, FlashPages, Snapshot, StreamRing, StreamSample,
    Watchdog,
};
use firmware::runner::Loop;
use firmware::slots::{Slot, SLOT_BYTES};
use model_core::control::ValidatedConfig;
use model_core::protocol::device::StatusFigures;
use model_core::protocol::mode_code;

/// Simulated time, µs since the board started; set by the server before every sample.
#[derive(Default)]
pub struct SimClock {
    now_us: Cell<u64>,
}

impl SimClock {
    pub fn set(&self, us: u64) {
        self.now_us.set(us);
    }
}

impl Clock for SimClock {
    fn now_us(&self) -> u64 {
        self.now_us.get()
    }
    fn at(&self, at_us: u64) -> impl Future<Output = ()> {
        // Polled after every sample: no waker to register.
        poll_fn(move |_| if self.now_us.get() >= at_us { Poll::Ready(()) } else { Poll::Pending })
    }
}

/// STM32G474 flash timing (DS12288 rev 6, table "Flash memory characteristics", typical):
/// page erase, µs.
pub const ERASE_US: u64 = 22_020;
/// Programming one double-word, µs.
pub const PROGRAM_DW_US: u64 = 82;

/// The two configuration slots, kept across watchdog resets (blank at start).
pub struct SimFlash<'a> {
    clock: &'a SimClock,
    a: RefCell<[u8; SLOT_BYTES]>,
    b: RefCell<[u8; SLOT_BYTES]>,
}

impl<'a> SimFlash<'a> {
    pub fn new(clock: &'a SimClock) -> Self {
        Self { clock, a: RefCell::new([0xFF; SLOT_BYTES]), b: RefCell::new([0xFF; SLOT_BYTES]) }
    }

    fn slot(&self, slot: Slot) -> &RefCell<[u8; SLOT_BYTES]> {
        match slot {
            Slot::A => &self.a,
            Slot::B => &self.b,
        }
    }
}

impl FlashPages for SimFlash<'_> {
    fn read(&self, slot: Slot) -> Result<[u8; SLOT_BYTES], EccError> {
        Ok(*self.slot(slot).borrow())
    }

    async fn program(&self, slot: Slot, image: &[u8; SLOT_BYTES]) -> Result<(), FlashFault> {
        let c = self.clock;
        c.at(c.now_us() + ERASE_US).await;
        *self.slot(slot).borrow_mut() = [0xFF; SLOT_BYTES];
        for (i, dw) in image.chunks_exact(8).enumerate() {
            if dw.iter().all(|b| *b == 0xFF) {
                continue;
            }
            c.at(c.now_us() + PROGRAM_DW_US).await;
            self.slot(slot).borrow_mut()[8 * i..8 * i + 8].copy_from_slice(dw);
        }
        Ok(())
    }
}

/// A committed controller waiting for the bridge to be off, with its page CRC.
pub type Pending = (Loop, ValidatedConfig, u32);

/// The control interrupt's shared state (the board's atomics and cells).
pub struct SimControl {
    pub reference: Cell<f32>,
    pub enable: Cell<bool>,
    pub reset: Cell<bool>,
    pub stalled: Cell<bool>,
    pub slow_due: Cell<bool>,
    pub samples: Cell<u32>,
    pub overruns: Cell<u32>,
    /// The latest sample (the status reply's figures).
    pub last: Cell<Snapshot>,
    pub pending: RefCell<Option<Box<Pending>>>,
    /// Which configuration runs (`store::source_code`).
    pub source: Cell<u32>,
    pub decimation: Cell<u32>,
    pub stream: RefCell<StreamRing>,
}

impl SimControl {
    pub fn new(running: Option<(Slot, u32)>, damaged: bool) -> Self {
        Self {
            reference: Cell::new(0.0),
            enable: Cell::new(false),
            reset: Cell::new(false),
            stalled: Cell::new(damaged),
            slow_due: Cell::new(false),
            samples: Cell::new(0),
            overruns: Cell::new(0),
            last: Cell::new(Snapshot::EMPTY),
            pending: RefCell::new(None),
            source: Cell::new(store::source_code(running, damaged)),
            decimation: Cell::new(0),
            stream: RefCell::new(StreamRing::new()),
        }
    }
}

impl ControlPort for SimControl {
    fn set_reference(&self, t: f32) {
        self.reference.set(t);
    }
    fn set_enable(&self, on: bool) {
        self.enable.set(on);
    }
    fn enabled(&self) -> bool {
        self.enable.get()
    }
    fn request_reset(&self) {
        self.reset.set(true);
    }
    /// The latest sample's figures (as the board's: stored every period).
    fn status(&self) -> StatusFigures {
        let o = self.last.get().out;
        StatusFigures {
            mode: mode_code(o.mode),
            fault: o.fault.code(),
            overruns: self.overruns.get(),
            torque_est: o.torque_est,
        }
    }
    fn snapshot(&self) -> Snapshot {
        self.last.get()
    }
    fn overruns(&self) -> u32 {
        self.overruns.get()
    }
    fn samples(&self) -> u32 {
        self.samples.get()
    }
    fn stalled(&self) -> bool {
        self.stalled.get()
    }
    fn stall(&self) {
        self.stalled.set(true);
    }
    fn request_slow_pass(&self) {
        self.slow_due.set(true);
    }
    fn hand_over(&self, lp: Loop, cfg: ValidatedConfig, crc: u32) {
        *self.pending.borrow_mut() = Some(Box::new((lp, cfg, crc)));
    }
    fn running(&self, running: Option<(Slot, u32)>, damaged: bool) {
        self.source.set(store::source_code(running, damaged));
    }
    fn set_stream_decimation(&self, d: u32) {
        self.decimation.set(d);
    }
    fn pop_stream(&self) -> Option<StreamSample> {
        self.stream.borrow_mut().pop()
    }
}

/// Independent watchdog timeout, µs (the board's).
pub const WATCHDOG_US: u64 = firmware::application::watchdog::TIMEOUT_US as u64;

/// The modelled IWDG: once started, it expires [`WATCHDOG_US`] after the last pet.
pub struct SimWatchdog<'a> {
    clock: &'a SimClock,
    last_pet: &'a Cell<Option<u64>>,
}

impl<'a> SimWatchdog<'a> {
    /// A watchdog whose last pet the server reads from `last_pet`.
    pub fn new(clock: &'a SimClock, last_pet: &'a Cell<Option<u64>>) -> Self {
        last_pet.set(None);
        Self { clock, last_pet }
    }
}

/// The watchdog started at or last petted at `last_pet` has expired at `now_us`.
pub fn expired(last_pet: Option<u64>, now_us: u64) -> bool {
    last_pet.is_some_and(|t| now_us.saturating_sub(t) > WATCHDOG_US)
}

impl Watchdog for SimWatchdog<'_> {
    fn start(&mut self) {
        self.last_pet.set(Some(self.clock.now_us()));
    }
    fn pet(&mut self) {
        self.last_pet.set(Some(self.clock.now_us()));
    }
}

/// The log on stderr (the 10 Hz telemetry line left out).
pub struct Stderr;

impl Events for Stderr {
    fn event(&self, e: Event) {
        match e {
            Event::Telemetry(_) => {}
            e => eprintln!("virtual board: {e:?}"),
        }
    }
}

/// Bytes from the host to the board (the UART's receive buffer).
pub struct PipeRx<'a>(pub &'a RefCell<VecDeque<u8>>);

/// Bytes from the board to the host (the UART's transmit buffer).
pub struct PipeTx<'a>(pub &'a RefCell<Vec<u8>>);

impl embedded_io_async::ErrorType for PipeRx<'_> {
    type Error = Infallible;
}

impl embedded_io_async::ErrorType for PipeTx<'_> {
    type Error = Infallible;
}

impl embedded_io_async::Read for PipeRx<'_> {
    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, Infallible> {
        poll_fn(|_| {
            let mut q = self.0.borrow_mut();
            if buf.is_empty() {
                return Poll::Ready(Ok(0));
            }
            if q.is_empty() {
                return Poll::Pending;
            }
            let n = buf.len().min(q.len());
            for (d, s) in buf.iter_mut().zip(q.drain(..n)) {
                *d = s;
            }
            Poll::Ready(Ok(n))
        })
        .await
    }
}

impl embedded_io_async::Write for PipeTx<'_> {
    async fn write(&mut self, buf: &[u8]) -> Result<usize, Infallible> {
        self.0.borrow_mut().extend_from_slice(buf);
        Ok(buf.len())
    }
    async fn flush(&mut self) -> Result<(), Infallible> {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_watchdog_expires_only_after_its_timeout_without_a_pet() {
        assert!(!expired(None, 1_000_000), "not started");
        assert!(!expired(Some(100), 100 + WATCHDOG_US));
        assert!(expired(Some(100), 101 + WATCHDOG_US));
    }
}
