//! Opening a port: a serial device (921 600 Bd, 8N1), `tcp:HOST:PORT`, or `can:IFACE`.

use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::Duration;

use super::error::LinkError;

/// A byte stream to the board. Reads time out after [`POLL`] with `TimedOut`/`WouldBlock`.
pub trait Stream: Read + Write + Send {}
impl<T: Read + Write + Send> Stream for T {}

/// How long one read waits.
pub const POLL: Duration = Duration::from_millis(5);
/// The UART link's baud rate (the firmware's; the ST-LINK virtual COM port carries it).
pub use firmware::application::serial::BAUD;

/// Open `port`.
pub fn open(port: &str) -> Result<Box<dyn Stream>, LinkError> {
    if let Some(addr) = port.strip_prefix("tcp:") {
        if !addr.contains(':') {
            return Err(LinkError::BadPort(port.to_owned()));
        }
        let s = TcpStream::connect(addr).map_err(|source| LinkError::Connect { port: port.to_owned(), source })?;
        let io = |source| LinkError::Io { port: port.to_owned(), source };
        s.set_nodelay(true).map_err(io)?;
        s.set_read_timeout(Some(POLL)).map_err(io)?;
        return Ok(Box::new(s));
    }
    if let Some(iface) = port.strip_prefix("can:") {
        return open_can(iface);
    }
    if port.is_empty() || port.contains(':') {
        return Err(LinkError::BadPort(port.to_owned()));
    }
    let s = serialport::new(port, BAUD)
        .timeout(POLL)
        .open()
        .map_err(|source| LinkError::Serial { port: port.to_owned(), source })?;
    Ok(Box::new(s))
}

/// `can:IFACE` on Linux: a SocketCAN raw socket ([`super::can`]).
#[cfg(target_os = "linux")]
fn open_can(iface: &str) -> Result<Box<dyn Stream>, LinkError> {
    match super::can::CanStream::open(iface, POLL) {
        Ok(s) => Ok(Box::new(s)),
        Err(source) => Err(LinkError::CanOpen { iface: iface.to_owned(), source }),
    }
}

#[cfg(not(target_os = "linux"))]
fn open_can(iface: &str) -> Result<Box<dyn Stream>, LinkError> {
    Err(LinkError::NoCan { iface: iface.to_owned() })
}
