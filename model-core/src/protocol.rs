//! The command interface of the clutch driver: a small binary protocol that fits classic
//! CAN frames (8 data bytes; FDCAN, or the same payloads over a UART with a length byte in
//! front). Pure encode/decode, `no_std`, so the firmware and host tools share it and it is
//! tested on the host.
//!
//! Every frame starts with a command byte; numbers are little-endian.
//!
//! | byte 0 | name | bytes 1.. | reply |
//! | --- | --- | --- | --- |
//! | `0x01` | set torque | f32 reference (N·m; A in current mode) | none (streamed at up to the loop rate) |
//! | `0x02` | enable | u8: 1 drive, 0 bridge off | ack |
//! | `0x03` | reset | – (clears a latched fault, recalibrates) | ack |
//! | `0x04` | get status | – | status |
//! | `0x05` | telemetry | u16 decimation (every n-th control sample; 0 stops) | ack; then [`telemetry`] frames |
//! | `0x10` | config begin | u16 page length (≤ 2048) | ack |
//! | `0x11` | config data | u16 offset, 1–5 bytes | none (nack on a bad offset) |
//! | `0x13` | config query | – | page CRC (u32 CRC-32 of the running page's bytes through its own CRC; 0: compiled-in defaults) |
//! | `0x12` | config commit | u32 CRC-32 of the transferred bytes | ack after it is validated, written to flash and swapped in; nack otherwise |
//!
//! Replies: `0x81` status (u8 mode, u8 fault code, u8 overruns (saturating), f32 torque
//! estimate N·m),
//! `0x82` ack (u8 command), `0x83` nack (u8 command, u8 [`Nack`] reason). The firmware
//! answers on its reply identifier (see the firmware README); a configuration is only
//! accepted while the bridge is off.

//!
//! On a byte stream (the UART link, TCP for the virtual board) every frame is framed by
//! [`frame`] (COBS, CRC-32); [`device`] is the board's command handling, [`telemetry`] the
//! signal stream (UART/TCP only: its frames are longer than a CAN frame).

use crate::control::page::{ConfigImage, PageError, PAGE_BYTES};

pub mod device;
pub mod frame;
pub mod telemetry;

/// Largest frame.
pub const FRAME: usize = 8;
/// Payload bytes of one config-data frame.
pub const CHUNK: usize = 5;

/// A command from the robot controller.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Command {
    SetTorque(f32),
    Enable(bool),
    Reset,
    GetStatus,
    Telemetry { decimation: u16 },
    ConfigBegin { len: u16 },
    ConfigData { offset: u16, len: u8, data: [u8; CHUNK] },
    ConfigCommit { crc: u32 },
    ConfigQuery,
}

/// Why a frame or a request was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Nack {
    /// Unknown command byte.
    Unknown = 1,
    /// Wrong length for the command, or a non-finite number.
    Malformed = 2,
    /// Config data outside the announced page, or commit without begin.
    Sequence = 3,
    /// The transferred bytes do not match the commit's CRC.
    TransferCrc = 4,
    /// The page does not decode or validate (magic, version, CRC, settings, model).
    InvalidPage = 5,
    /// Not allowed now (configuration while the bridge is driven).
    Busy = 6,
    /// Writing the flash page failed.
    Flash = 7,
}

/// A reply to the robot controller.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Response {
    /// Overruns since start-up, saturating at 255.
    Status {
        mode: u8,
        fault: u8,
        overruns: u8,
        torque_est: f32,
    },
    Ack(u8),
    Nack(u8, Nack),
    /// CRC-32 of the running page (`0x84`).
    PageCrc(u32),
}

fn le4(b: &[u8]) -> Option<[u8; 4]> {
    match b {
        [a, b, c, d] => Some([*a, *b, *c, *d]),
        _ => None,
    }
}

impl Command {
    /// The command byte.
    pub const fn code(&self) -> u8 {
        match self {
            Self::SetTorque(_) => 0x01,
            Self::Enable(_) => 0x02,
            Self::Reset => 0x03,
            Self::GetStatus => 0x04,
            Self::Telemetry { .. } => 0x05,
            Self::ConfigBegin { .. } => 0x10,
            Self::ConfigData { .. } => 0x11,
            Self::ConfigCommit { .. } => 0x12,
            Self::ConfigQuery => 0x13,
        }
    }

    /// Decode one frame.
    pub fn decode(frame: &[u8]) -> Result<Self, Nack> {
        let (&code, rest) = frame.split_first().ok_or(Nack::Malformed)?;
        Ok(match (code, rest) {
            (0x01, r) => {
                let v = f32::from_le_bytes(le4(r).ok_or(Nack::Malformed)?);
                if !v.is_finite() {
                    return Err(Nack::Malformed);
                }
                Self::SetTorque(v)
            }
            (0x02, [e]) if *e <= 1 => Self::Enable(*e == 1),
            (0x03, []) => Self::Reset,
            (0x04, []) => Self::GetStatus,
            (0x05, [a, b]) => Self::Telemetry { decimation: u16::from_le_bytes([*a, *b]) },
            (0x10, [a, b]) => Self::ConfigBegin { len: u16::from_le_bytes([*a, *b]) },
            (0x11, [a, b, data @ ..]) if !data.is_empty() && data.len() <= CHUNK => {
                let mut d = [0u8; CHUNK];
                for (o, i) in d.iter_mut().zip(data) {
                    *o = *i;
                }
                Self::ConfigData { offset: u16::from_le_bytes([*a, *b]), len: data.len() as u8, data: d }
            }
            (0x12, r) => Self::ConfigCommit { crc: u32::from_le_bytes(le4(r).ok_or(Nack::Malformed)?) },
            (0x13, []) => Self::ConfigQuery,
            (0x01..=0x05 | 0x10..=0x13, _) => return Err(Nack::Malformed),
            _ => return Err(Nack::Unknown),
        })
    }

    /// Encode into `out`; returns the frame length.
    pub fn encode(&self, out: &mut [u8; FRAME]) -> usize {
        let mut w = Writer { out, n: 0 };
        w.put(&[self.code()]);
        match *self {
            Self::SetTorque(v) => w.put(&v.to_le_bytes()),
            Self::Enable(e) => w.put(&[u8::from(e)]),
            Self::Reset | Self::GetStatus | Self::ConfigQuery => {}
            Self::Telemetry { decimation } => w.put(&decimation.to_le_bytes()),
            Self::ConfigBegin { len } => w.put(&len.to_le_bytes()),
            Self::ConfigData { offset, len, data } => {
                w.put(&offset.to_le_bytes());
                w.put(data.get(..usize::from(len).min(CHUNK)).unwrap_or(&[]));
            }
            Self::ConfigCommit { crc } => w.put(&crc.to_le_bytes()),
        }
        w.n
    }
}

struct Writer<'a> {
    out: &'a mut [u8; FRAME],
    n: usize,
}

impl Writer<'_> {
    fn put(&mut self, bytes: &[u8]) {
        for b in bytes {
            if let Some(o) = self.out.get_mut(self.n) {
                *o = *b;
                self.n += 1;
            }
        }
    }
}

impl Response {
    /// Encode into `out`; returns the frame length.
    pub fn encode(&self, out: &mut [u8; FRAME]) -> usize {
        let mut w = Writer { out, n: 0 };
        match *self {
            Self::Status { mode, fault, overruns, torque_est } => {
                w.put(&[0x81, mode, fault, overruns]);
                w.put(&torque_est.to_le_bytes());
            }
            Self::Ack(cmd) => w.put(&[0x82, cmd]),
            Self::Nack(cmd, why) => w.put(&[0x83, cmd, why as u8]),
            Self::PageCrc(crc) => {
                w.put(&[0x84]);
                w.put(&crc.to_le_bytes());
            }
        }
        w.n
    }

    /// Decode a reply (host side).
    pub fn decode(frame: &[u8]) -> Option<Self> {
        Some(match frame {
            [0x81, mode, fault, overruns, t0, t1, t2, t3] => Self::Status {
                mode: *mode,
                fault: *fault,
                overruns: *overruns,
                torque_est: f32::from_le_bytes([*t0, *t1, *t2, *t3]),
            },
            [0x82, cmd] => Self::Ack(*cmd),
            [0x84, a, b, c, d] => Self::PageCrc(u32::from_le_bytes([*a, *b, *c, *d])),
            [0x83, cmd, why] => Self::Nack(
                *cmd,
                match why {
                    1 => Nack::Unknown,
                    2 => Nack::Malformed,
                    3 => Nack::Sequence,
                    4 => Nack::TransferCrc,
                    5 => Nack::InvalidPage,
                    6 => Nack::Busy,
                    _ => Nack::Flash,
                },
            ),
            _ => return None,
        })
    }
}

/// The status byte of a mode (`ControlOutput::mode`): 0 init, 1 calibrating, 2 running,
/// 3 disabled, 4 fault.
pub const fn mode_code(m: crate::control::Mode) -> u8 {
    use crate::control::Mode;
    match m {
        Mode::Init => 0,
        Mode::Calibrating => 1,
        Mode::Running => 2,
        Mode::Disabled => 3,
        Mode::Fault(_) => 4,
    }
}

/// Collects a configuration page from `ConfigBegin` / `ConfigData` / `ConfigCommit`.
#[derive(Clone, Debug)]
pub struct PageAssembler {
    buf: [u8; PAGE_BYTES],
    len: usize,
    active: bool,
}

impl Default for PageAssembler {
    fn default() -> Self {
        Self { buf: [0xFF; PAGE_BYTES], len: 0, active: false }
    }
}

impl PageAssembler {
    /// Start a transfer of `len` bytes.
    pub fn begin(&mut self, len: u16) -> Result<(), Nack> {
        let len = usize::from(len);
        if len == 0 || len > PAGE_BYTES {
            return Err(Nack::Malformed);
        }
        *self = Self { len, active: true, ..Self::default() };
        Ok(())
    }

    /// Store a chunk.
    pub fn data(&mut self, offset: u16, bytes: &[u8]) -> Result<(), Nack> {
        let at = usize::from(offset);
        match (self.active, self.buf.get_mut(at..at + bytes.len())) {
            (true, Some(dst)) if at + bytes.len() <= self.len => {
                dst.copy_from_slice(bytes);
                Ok(())
            }
            _ => Err(Nack::Sequence),
        }
    }

    /// The page bytes received (0xFF beyond what was sent).
    pub fn bytes(&self) -> &[u8; PAGE_BYTES] {
        &self.buf
    }

    /// End the transfer: the bytes must match `crc` (CRC-32 of the `len` bytes sent), then
    /// the page must decode and validate. Returns the page bytes and the image.
    pub fn commit(&mut self, crc: u32) -> Result<(&[u8; PAGE_BYTES], ConfigImage), Nack> {
        if !self.active {
            return Err(Nack::Sequence);
        }
        self.active = false;
        let sent = self.buf.get(..self.len).unwrap_or(&[]);
        if !crate::control::config::crc32_update(!0, sent) != crc {
            return Err(Nack::TransferCrc);
        }
        let img = ConfigImage::decode(&self.buf).map_err(|_: PageError| Nack::InvalidPage)?;
        Ok((&self.buf, img))
    }
}

#[cfg(test)]
mod tests;
