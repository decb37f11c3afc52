//! `hil-sim virtual-board`: the firmware's application logic on the host, against the
//! simulated clutch, in simulated real time, answering on a TCP port exactly as the board
//! answers on its UART (frames of `model_core::protocol::frame`).
//!
//! What runs is the firmware's own code: the command handling
//! (`model_core::protocol::device::Device`, which the firmware's link task calls), the
//! controller of a page for every built-in model (`firmware::runner::Loop`), the A/B
//! configuration slots with their commit record (`firmware::slots`), the board checks of a
//! page (`firmware::bringup::check_board`), the command timeout (`firmware::link`), and the
//! slow supervisor pass at 1 kHz; the plant and the sample-by-sample bench are
//! `closed_loop::rig`, which `hil-sim loop` steps too. `board.rs` is the board's state,
//! `server.rs` the socket and the clock.

pub mod board;
pub mod server;

pub use board::{Journal, VirtualBoard};
pub use server::{serve, ServeError, ServeOptions};
