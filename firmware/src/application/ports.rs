//! The few things the application needs from the chip (or from the host that stands in for
//! it): time, the configuration flash, the control interrupt's shared state, the watchdog, a
//! CAN port and a log. The board implements them over its peripherals (`firmware` binary,
//! `app.rs`), `hil-sim virtual-board` over the simulated clutch. Every call is static
//! dispatch (the application is generic over them); none of them is used by the control
//! interrupt itself.

use core::future::Future;

use model_core::control::ValidatedConfig;
use model_core::protocol::device::StatusFigures;

use super::stream::{Snapshot, StreamSample};
use crate::runner::Loop;
use crate::slots::{Slot, SlotState, SLOT_BYTES};

/// Monotonic time since start-up.
pub trait Clock {
    /// µs since start-up.
    fn now_us(&self) -> u64;
    /// Resolves once [`Clock::now_us`] has reached `at_us`.
    fn at(&self, at_us: u64) -> impl Future<Output = ()>;
}

/// A double-word of a slot had an uncorrectable ECC error (a program cut by a reset).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EccError;

/// The flash refused an erase or program (the raw status register, for the log).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct FlashFault(pub u32);

/// The two configuration slots ([`crate::slots`]). `&self`: both link tasks hold it; the
/// application never programs from two tasks at once.
pub trait FlashPages {
    /// The slot's bytes.
    fn read(&self, slot: Slot) -> Result<[u8; SLOT_BYTES], EccError>;
    /// Erase the slot and program `image` (the commit record, its last double-word, last),
    /// taking the chip's time: the waits yield.
    fn program(&self, slot: Slot, image: &[u8; SLOT_BYTES]) -> impl Future<Output = Result<(), FlashFault>>;
}

/// What the tasks exchange with the control interrupt (atomics and cells on the board).
pub trait ControlPort {
    /// Torque reference, N·m (A in current mode).
    fn set_reference(&self, t: f32);
    /// Drive enable as commanded.
    fn set_enable(&self, on: bool);
    fn enabled(&self) -> bool;
    /// Clear a latched fault at the next step.
    fn request_reset(&self);
    /// The figures of a status reply (mode, fault, overruns, estimate).
    fn status(&self) -> StatusFigures;
    /// The decimated snapshot for the log.
    fn snapshot(&self) -> Snapshot;
    /// Control steps that missed their deadline since start-up.
    fn overruns(&self) -> u32;
    /// Samples processed since start-up (the watchdog's sign of life).
    fn samples(&self) -> u32;
    /// The stall is latched (bridge held off until a reset command).
    fn stalled(&self) -> bool;
    /// Bridge to its safe state and the stall latched.
    fn stall(&self);
    /// Ask for one slow supervisor pass after the next compare write.
    fn request_slow_pass(&self);
    /// A committed controller (page CRC `crc`), swapped in between two samples while the
    /// bridge is off.
    fn hand_over(&self, lp: Loop, cfg: ValidatedConfig, crc: u32);
    /// Which configuration runs now (for the debugger: `running` slot and commit, or the
    /// defaults, `damaged` when the slots held nothing usable).
    fn running(&self, running: Option<(Slot, u32)>, damaged: bool);
    /// Every `d`-th sample into the stream (0: none).
    fn set_stream_decimation(&self, d: u32);
    /// The oldest streamed sample.
    fn pop_stream(&self) -> Option<StreamSample>;
}

/// The independent watchdog.
pub trait Watchdog {
    /// Start it (it cannot be stopped again).
    fn start(&mut self);
    fn pet(&mut self);
}

/// One classic CAN frame on a standard identifier.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CanFrame {
    /// 11-bit identifier.
    pub id: u16,
    pub len: u8,
    pub data: [u8; 8],
}

impl CanFrame {
    /// A frame of `data` (at most 8 bytes; `None` beyond).
    pub fn new(id: u16, data: &[u8]) -> Option<Self> {
        let mut d = [0u8; 8];
        d.get_mut(..data.len())?.copy_from_slice(data);
        Some(Self { id, len: data.len() as u8, data: d })
    }

    pub fn data(&self) -> &[u8] {
        self.data.get(..usize::from(self.len)).unwrap_or(&[])
    }
}

/// A bus error the controller reported while receiving (the task waits 1 ms, then reads on).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BusError;

/// The CAN port (acceptance filter in the port: extended frames are never delivered).
pub trait CanPort {
    fn recv(&mut self) -> impl Future<Output = Result<CanFrame, BusError>>;
    fn send(&mut self, frame: &CanFrame) -> impl Future<Output = ()>;
}

/// What the application reports (defmt on the board, a line on the host's stderr).
#[derive(Clone, Copy, Debug)]
pub enum Event {
    /// What the two slots hold at start-up.
    Slots(SlotState, SlotState),
    /// Booting slot `0`'s commit `1`.
    Loaded(Slot, u32),
    /// No slot holds a usable page: defaults, drive refused until a commit.
    Damaged,
    /// Blank slots: the compiled-in defaults.
    Blank,
    /// No command for `COMMAND_TIMEOUT_MS` with the drive enabled: released.
    Released,
    /// Programming slot `0` failed.
    CommitFailed(Slot, FlashFault),
    /// Slot `0` reads back as `1` after programming.
    ReadBack(Slot, SlotState),
    /// A new page runs: model id, slot, commit.
    Committed(&'static str, Slot, u32),
    /// The control interrupt stopped: bridge off, the watchdog will reset.
    Stalled,
    /// The 10 Hz telemetry snapshot.
    Telemetry(Snapshot),
    /// Missed deadlines: total, new since the last report.
    Overruns(u32, u32),
    /// A CAN bus error while receiving.
    Bus,
}

/// Where [`Event`]s go.
pub trait Events {
    fn event(&self, e: Event);
}
