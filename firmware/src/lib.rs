//! The firmware's pure logic, compiled for the board and for the host (where its unit tests
//! and the firmware-in-the-loop comparison in `tests/` use it): no peripheral access here,
//! only decisions. The board-facing code is the `firmware` binary (`main.rs`: `app`,
//! `board`, `controller`, `safety`), the only place that touches registers.
//!
//! - [`application`]: the application's tasks (command links, configuration store,
//!   supervisor, telemetry, watchdog) over a few port traits the board (and
//!   `hil-sim virtual-board`) implements.
//! - [`slots`]: the A/B configuration pages (which one boots, where a commit goes).
//! - [`link`]: the command timeout (the host disappearing disables the drive).
//! - [`can_timing`]: FDCAN nominal bit timing and its oscillator tolerance.
//! - [`bringup`]: board scaling (supply, over-current comparator threshold), checks of a
//!   configuration against the timer, the reset cause, the compiled-in configuration.
//! - [`bridge`]: when the main output may be enabled (compare values first, MOE a period
//!   later) and the latched stall.
//! - [`runner`]: the controller of a page, for every model that maps the field to torque.
#![cfg_attr(not(test), no_std)]

pub mod application;
pub mod bridge;
pub mod bringup;
pub mod can_timing;
pub mod link;
pub mod runner;
pub mod slots;
