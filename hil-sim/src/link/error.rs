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
    #[error("{port}: the board stopped answering while {what} (no frame for {ms} ms)")]
    Silent { port: String, what: &'static str, ms: u64 },
    #[error("{port}: {what}: {n} frames in a row failed their CRC (line noise, or another program on the port?)")]
    Crc { port: String, what: &'static str, n: u32 },
    #[error("{port}: the board refused {what}: {why}")]
    Refused { port: String, what: &'static str, why: &'static str },
    #[error("{port}: unexpected reply to {what}: {reply}")]
    Unexpected { port: String, what: &'static str, reply: String },
    #[error("{port}: {source}")]
    Io { port: String, source: std::io::Error },
    #[error(transparent)]
    Page(#[from] crate::io::config_page::PageBuildError),
    #[error(transparent)]
    Params(#[from] crate::io::params_file::ParamsFileError),
    #[error("{}: {why}", path.display())]
    Profile { path: PathBuf, why: String },
    #[error("{}: {source}", path.display())]
    Write { path: PathBuf, source: std::io::Error },
    #[error("{port}: verify: the board runs a page with CRC-32 {got:#010x}, the one sent has {want:#010x}")]
    Verify { port: String, want: u32, got: u32 },
}
