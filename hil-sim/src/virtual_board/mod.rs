//! `hil-sim virtual-board`: the firmware's application logic on the host, against the
//! simulated clutch, in simulated real time, answering on a TCP port exactly as the board
//! answers on its UART (frames of `model_core::protocol::frame`).
//!
//! What runs is the firmware's own application (`firmware::application`: the serial link
//! task with the command handling, the configuration store with its A/B flash slots, CRC
//! and commit record, the command timeout, the supervisor, telemetry and watchdog tasks)
//! over host ports (`ports.rs`: simulated clock, flash with the G474's erase and program
//! times, the control interrupt's cells, a modelled watchdog, the UART as two pipes),
//! under a single-threaded executor in simulated time (`server.rs`); the control
//! interrupt is `board.rs`, one sample of `closed_loop::rig` (the bench `hil-sim loop`
//! steps) with the controller of the page (`firmware::runner::Loop`).

pub mod board;
pub mod ports;
pub mod server;

pub use board::{Journal, VirtualBoard};
pub use server::{serve, ServeError, ServeOptions};
