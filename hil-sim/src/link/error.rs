//! What goes wrong on the link, each as one line that names the port.

use std::path::PathBuf;

use thiserror::Error;

#[derive(Debug, Error)]
pub enum LinkError {
    #[error("port `{0}`: expected a serial device (e.g. /dev/ttyACM0), tcp:HOST:PORT or can:IFACE")]
    BadPort(String),
    #[error("{port}: cannot connect: {source}")]
    Connect { port: String, source: std::io::Error },
    #[error("{port}: cannot open the serial device: {source}")]
    Serial { port: String, source: serialport::Error },
    #[error("can:{iface}: SocketCAN exists on Linux only; use the board's USB serial port (/dev/ttyACM0)")]
    NoCan { iface: String },
    #[error("can:{iface}: cannot open the SocketCAN interface (a CAN adapter at the board's 1 Mbit/s: `ip link set {iface} up type can bitrate 1000000`)")]
    CanOpen { iface: String, source: std::io::Error },
    #[error("{port}: no answer to {what} within {ms} ms (board off, firmware not running, or the wrong port?)")]
    Timeout { port: String, what: &'static str, ms: u64 },
    #[error("{port}: {what} was not acknowledged within {ms} ms, so it did not run: each attempt's deadline has passed on the board (board off, or the line too slow?)")]
    NotRun { port: String, what: &'static str, ms: u64 },
    #[error("{port}: the board is controlled by another host (its session did not end within {ms} ms; wait until it is done, or stop it)")]
    Held { port: String, ms: u64 },
    #[error("{port}: the board closed the connection")]
    Closed { port: String },
    #[error("{port}: no frame can carry {what} (a reference beyond ±8000 N·m, or not a number)")]
    Unsendable { port: String, what: String },
    #[error("{port}: the board stopped answering while {what} (no frame for {ms} ms)")]
    Silent { port: String, what: &'static str, ms: u64 },
    #[error("{port}: {what}: {n} frames in a row failed their CRC (line noise, or another program on the port?)")]
    Crc { port: String, what: &'static str, n: u32 },
    #[error("{port}: the board refused {what}: {why}")]
    Refused { port: String, what: &'static str, why: &'static str, reason: model_core::protocol::Nack },
    #[error("{port}: unexpected reply to {what}: {reply}")]
    Unexpected { port: String, what: &'static str, reply: String },
    #[error("{port}: {source}")]
    Io { port: String, source: std::io::Error },
    #[error(transparent)]
    Page(#[from] crate::io::config_page::PageBuildError),
    #[error(transparent)]
    Physics(#[from] crate::io::page_physics::PagePhysicsError),
    #[error(transparent)]
    Params(#[from] crate::io::params_file::ParamsFileError),
    #[error("{}: {why}", path.display())]
    Profile { path: PathBuf, why: String },
    #[error("{}: {source}", path.display())]
    Write { path: PathBuf, source: std::io::Error },
    #[error("{port}: no answer to the commit within {ms} ms; {state}")]
    CommitUnanswered { port: String, ms: u64, state: PageState },
    #[error("{why}")]
    Request { why: String },
    #[error(transparent)]
    Output { source: crate::io::output::OutputError },
    #[error("the recording ended early: {why}; {span} kept in {}", file.display())]
    Partial { why: String, span: String, file: PathBuf, kept: usize },
    #[error("{port}: verify: the board runs a page with CRC-32 {got:#010x}, the one sent has {want:#010x}")]
    Verify { port: String, want: u32, got: u32 },
}

/// Which page runs after a commit that went unanswered.
#[derive(Debug)]
pub enum PageState {
    /// The board answers the page query with a page that is not the one sent.
    Old { crc: u32, before: u32 },
    /// The board answers nothing: which page runs is unknown.
    Unknown,
}

impl std::fmt::Display for PageState {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Old { crc, before } if crc == before => {
                write!(f, "the board still runs the page it ran before ({crc:#010x}): the load did not take effect")
            }
            Self::Old { crc, .. } => write!(f, "the board runs page {crc:#010x}, neither the one sent nor the one before"),
            Self::Unknown => write!(
                f,
                "the board does not answer the page query either: which page runs is UNKNOWN (power-cycle or check with `board status` before driving)"
            ),
        }
    }
}
