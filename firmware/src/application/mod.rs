//! The firmware's application, compiled for the board and for the host: the command links
//! (a byte link with the frames of `model_core::protocol::frame`, and CAN), the
//! configuration store (a page assembled, checked and committed to the A/B flash slots
//! with its CRC and commit record, read back, handed to the control interrupt), the
//! supervisor's slow-pass requests, the telemetry log, the watchdog's feeding policy and
//! the command timeout. It is generic over the few traits of [`ports`], which the board
//! implements over its peripherals (`app.rs` of the `firmware` binary keeps only the
//! embassy task wrappers and the peripheral set-up) and `hil-sim virtual-board` over the
//! simulated clutch, in simulated time. The control interrupt is not here: it stays the
//! board's, with no indirection in it.
//!
//! One file per task: [`serial`], [`can`], [`supervisor`], [`telemetry`], [`watchdog`];
//! [`store`] is the configuration store, [`links`] what the two links share (command
//! handling, timeout, the commit in progress).

pub mod can;
pub mod links;
pub mod ports;
pub mod serial;
pub mod store;
pub mod stream;
pub mod supervisor;
pub mod telemetry;
pub mod time;
pub mod watchdog;

pub use links::Shared;
pub use ports::{
    BusError, CanFrame, CanPort, Clock, ControlPort, EccError, Event, Events, FlashFault, FlashPages, Watchdog,
};
pub use stream::{Snapshot, StreamRing, StreamSample};

/// Everything a task needs: the board's ports and the state the tasks share. Copied into
/// every task (references only).
pub struct App<'a, C, F, P, E> {
    pub clock: &'a C,
    pub flash: &'a F,
    pub ctl: &'a P,
    pub events: &'a E,
    pub shared: &'a Shared,
}

impl<C, F, P, E> Clone for App<'_, C, F, P, E> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<C, F, P, E> Copy for App<'_, C, F, P, E> {}
