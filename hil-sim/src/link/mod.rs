//! The board link: the host side of the protocol in `model_core::protocol`, on a serial
//! device (the Nucleo's ST-LINK virtual COM port), `tcp:HOST:PORT` (the virtual board) or
//! `can:IFACE`. `port.rs` opens the byte stream (`can.rs`: CAN frames as one), `client.rs` frames commands and matches
//! replies (timeouts, CRC errors, lost telemetry), `load.rs` transfers a configuration
//! page, `record.rs` streams telemetry to a recording.

pub mod can;
pub mod client;
pub mod error;
pub mod load;
pub mod port;
pub mod record;

pub use client::{Link, LinkStats, Status};
pub use error::LinkError;
