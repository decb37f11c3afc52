//! The command interface of the clutch driver: a small binary protocol that fits classic
//! CAN frames (8 data bytes; FDCAN, or the same payloads over a UART with COBS and a
//! CRC-32, [`frame`]). Pure encode/decode, `no_std`, so the firmware and host tools share
//! it and it is tested on the host.
//!
//! Every frame starts with a command byte; numbers are little-endian.
//!
//! ## Sessions, sequence numbers, deadlines
//!
//! A command that can drive the clutch or change what drives it is **guarded**: it carries
//! a [`Guard`] (a 4-bit session, a 12-bit sequence number, a 16-bit deadline in ms of the
//! board's clock), and the board runs it only if the session is the one it granted, the
//! sequence number is ahead of the last it ran for that session, and the deadline has not
//! passed. A command that arrives late, twice, out of order or from a host that holds no
//! session is refused with its reason and never runs, so when the host gives up on a
//! command after its deadline, the host's "failed" is true. A host first claims the board
//! ([`Command::Claim`]); the reply names its session, the first sequence number and the
//! board's clock, from which the host writes deadlines. One host holds the board at a time;
//! the session ends on [`Command::Release`], or when the holder has sent nothing guarded
//! for [`session::IDLE_MS`]; the drive is released with it. Other hosts may read
//! (status, page CRC, limits, telemetry) and are told [`Nack::Held`] when they claim.
//!
//! | byte 0 | name | bytes 1.. | reply |
//! | --- | --- | --- | --- |
//! | `0x01` | set torque | guard, i24 reference (mN·m; mA in current mode) | nack only (streamed at up to 1 kHz) |
//! | `0x0A` | set torque, acknowledged | as `0x01` | ack |
//! | `0x02` | enable | guard, u8: 1 drive, 0 bridge off | ack (nack while a fault is latched) |
//! | `0x03` | reset | guard (clears a latched fault, recalibrates) | ack once cleared, nack while it persists |
//! | `0x04` | get status | – | status |
//! | `0x05` | telemetry | u16 decimation (every n-th control sample; 0 stops) | ack; then [`telemetry`] frames |
//! | `0x06` | claim | u16 nonce (the host's) | session, or nack [`Nack::Held`] |
//! | `0x07` | release | guard | ack (drive off, session ended) |
//! | `0x08` | heartbeat | guard (keeps the session and the drive alive) | nack only |
//! | `0x10` | config begin | guard, u16 page length (≤ 2048) | ack |
//! | `0x11` | config data | u16 offset, 1–5 bytes | nack only (a bad offset) |
//! | `0x12` | config commit | u32 CRC-32 of the transferred bytes | ack after it is validated, written to flash and swapped in; nack otherwise |
//! | `0x13` | config query | – | page CRC (u32 CRC-32 of the running page's bytes through its own CRC; 0: compiled-in defaults) |
//! | `0x14` | limits | – | limits |
//!
//! Config data and commit carry no guard of their own (a commit's frame is full): they
//! belong to the transfer a guarded begin opened, which ends with the session.
//!
//! Replies: `0x81` status (u8 mode, u8 fault code, u8 overruns (saturating), f32 torque
//! estimate N·m); `0x82` ack (u8 command, u16 tag, u16 board ms); `0x83` nack (u8 command,
//! u8 [`Nack`] reason, u16 tag, u16 board ms); `0x84` page CRC (u32); `0x85` session (u16
//! nonce, u16 tag of the first command, u16 board ms); `0x86` limits (f32 torque limit N·m
//! (A in current mode), u16 control rate Hz). The tag of an ack or nack is the guarded
//! command's (session and sequence number; 0 for an unguarded one), so a host knows which
//! of its commands ran; the board's clock in every ack and nack keeps the host's deadlines
//! on the board's time. A configuration is only accepted while the bridge is off.
//!
//! On a byte stream (the UART link, TCP for the virtual board) every frame is framed by
//! [`frame`] (COBS, CRC-32); [`device`] is the board's command handling, [`session`] the
//! session and guard checks, [`telemetry`] the signal stream (UART/TCP only: its frames
//! are longer than a CAN frame).

use crate::control::page::{ConfigImage, PageError, PAGE_BYTES};

pub mod device;
pub mod frame;
pub mod session;
pub mod telemetry;

pub use session::{Guard, Sessions};

/// Largest frame.
pub const FRAME: usize = 8;
/// Payload bytes of one config-data frame.
pub const CHUNK: usize = 5;

/// Largest |reference| a set-torque frame carries, N·m: inside the i24 range of mN·m
/// (±8,388.607) with room for the f32 rounding of the product.
pub const REFERENCE_MAX: f32 = 8_000.0;

/// A command from the robot controller.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Command {
    /// `reference` is a multiple of 1 mN·m within ±[`REFERENCE_MAX`] (see
    /// [`quantise_reference`]); `ack`: acknowledged (`0x0A`) or streamed (`0x01`).
    SetTorque {
        guard: Guard,
        reference: f32,
        ack: bool,
    },
    Enable {
        guard: Guard,
        on: bool,
    },
    Reset {
        guard: Guard,
    },
    GetStatus,
    Telemetry {
        decimation: u16,
    },
    Claim {
        nonce: u16,
    },
    Release {
        guard: Guard,
    },
    Heartbeat {
        guard: Guard,
    },
    ConfigBegin {
        guard: Guard,
        len: u16,
    },
    ConfigData {
        offset: u16,
        len: u8,
        data: [u8; CHUNK],
    },
    ConfigCommit {
        crc: u32,
    },
    ConfigQuery,
    Limits,
}

/// Why a frame or a request was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Nack {
    /// Unknown command byte.
    Unknown = 1,
    /// Wrong length for the command, or a number out of its range.
    Malformed = 2,
    /// Config data outside the announced page, or commit without begin.
    Sequence = 3,
    /// The transferred bytes do not match the commit's CRC.
    TransferCrc = 4,
    /// The page does not decode or validate (magic, version, CRC, settings, model).
    InvalidPage = 5,
    /// Not allowed now (configuration while the bridge is driven, or a commit in progress).
    Busy = 6,
    /// Writing the flash page failed.
    Flash = 7,
    /// The command's deadline had passed when it arrived (or lies further ahead than a
    /// host's clock can be wrong): it did not run.
    Expired = 8,
    /// Its sequence number is not ahead of the last one run (a duplicate or a reordered
    /// frame): it did not run.
    Stale = 9,
    /// It names no session the board holds (none claimed, ended, or another one).
    NoSession = 10,
    /// Another host holds the board.
    Held = 11,
    /// Enable refused: a fault is latched (reset first).
    Faulted = 12,
    /// Reset done, but the fault is still present (it latched again).
    FaultPresent = 13,
    /// The reference is beyond the running page's limit.
    OutOfRange = 14,
    /// The page would drive the clutch wrongly (its estimate is not finite, exceeds the
    /// rating, or does not increase with the field over the page's field range).
    Physics = 15,
}

impl Nack {
    /// Every reason, in code order.
    pub const ALL: [Self; 15] = [
        Self::Unknown,
        Self::Malformed,
        Self::Sequence,
        Self::TransferCrc,
        Self::InvalidPage,
        Self::Busy,
        Self::Flash,
        Self::Expired,
        Self::Stale,
        Self::NoSession,
        Self::Held,
        Self::Faulted,
        Self::FaultPresent,
        Self::OutOfRange,
        Self::Physics,
    ];

    /// The reason of a code (`None`: a reason this build does not know).
    pub fn from_code(code: u8) -> Option<Self> {
        Self::ALL.iter().copied().find(|n| *n as u8 == code)
    }
}

/// A reply to the robot controller.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Response {
    /// Overruns since start-up, saturating at 255.
    Status { mode: u8, fault: u8, overruns: u8, torque_est: f32 },
    /// Command `code` (guard tag `tag`, 0 unguarded) ran; the board's clock, ms (wraps).
    Ack { code: u8, tag: u16, now_ms: u16 },
    /// Command `code` (tag `tag`) did not run, and why.
    Nack { code: u8, why: Nack, tag: u16, now_ms: u16 },
    /// CRC-32 of the running page (`0x84`).
    PageCrc(u32),
    /// A claim granted: the host's nonce, the tag of its first guarded command, the clock.
    Session { nonce: u16, tag: u16, now_ms: u16 },
    /// The running page's reference limit (N·m; A in current mode) and control rate.
    Limits { reference_max: f32, control_hz: u16 },
}

/// `v` as the multiple of 1 mN·m a set-torque frame carries (`None`: not finite, or
/// beyond ±[`REFERENCE_MAX`]).
pub fn quantise_reference(v: f32) -> Option<f32> {
    i24_of(v).map(|m| m as f32 / 1000.0)
}

fn i24_of(v: f32) -> Option<i32> {
    if v.is_nan() || crate::math::abs(v) > REFERENCE_MAX {
        return None;
    }
    let m = v * 1000.0;
    // Round half away from zero without `round` (no_std): |m| ≤ 8.4e6 < 2^24, exact in i32.
    Some(if m >= 0.0 { (m + 0.5) as i32 } else { (m - 0.5) as i32 })
}

fn le2(b: &[u8]) -> Option<u16> {
    match b {
        [a, b] => Some(u16::from_le_bytes([*a, *b])),
        _ => None,
    }
}

fn le4(b: &[u8]) -> Option<[u8; 4]> {
    match b {
        [a, b, c, d] => Some([*a, *b, *c, *d]),
        _ => None,
    }
}

/// A guard and what follows it.
fn guarded(r: &[u8]) -> Option<(Guard, &[u8])> {
    let (g, rest) = r.split_at_checked(4)?;
    let tag = le2(g.get(..2)?)?;
    let deadline_ms = le2(g.get(2..4)?)?;
    Some((Guard::from_tag(tag, deadline_ms), rest))
}

impl Command {
    /// The command byte.
    pub const fn code(&self) -> u8 {
        match self {
            Self::SetTorque { ack: false, .. } => 0x01,
            Self::SetTorque { ack: true, .. } => 0x0A,
            Self::Enable { .. } => 0x02,
            Self::Reset { .. } => 0x03,
            Self::GetStatus => 0x04,
            Self::Telemetry { .. } => 0x05,
            Self::Claim { .. } => 0x06,
            Self::Release { .. } => 0x07,
            Self::Heartbeat { .. } => 0x08,
            Self::ConfigBegin { .. } => 0x10,
            Self::ConfigData { .. } => 0x11,
            Self::ConfigCommit { .. } => 0x12,
            Self::ConfigQuery => 0x13,
            Self::Limits => 0x14,
        }
    }

    /// The guard of a guarded command.
    pub const fn guard(&self) -> Option<Guard> {
        match *self {
            Self::SetTorque { guard, .. }
            | Self::Enable { guard, .. }
            | Self::Reset { guard }
            | Self::Release { guard }
            | Self::Heartbeat { guard }
            | Self::ConfigBegin { guard, .. } => Some(guard),
            _ => None,
        }
    }

    /// Decode one frame.
    pub fn decode(frame: &[u8]) -> Result<Self, Nack> {
        let (&code, rest) = frame.split_first().ok_or(Nack::Malformed)?;
        let m = Nack::Malformed;
        let g = || guarded(rest).ok_or(m);
        Ok(match code {
            0x01 | 0x0A => {
                let (guard, v) = g()?;
                let [a, b, c] = <[u8; 3]>::try_from(v).map_err(|_| m)?;
                // Sign-extend the 24-bit value.
                let milli = i32::from_le_bytes([a, b, c, 0]) << 8 >> 8;
                Self::SetTorque { guard, reference: milli as f32 / 1000.0, ack: code == 0x0A }
            }
            0x02 => match g()? {
                (guard, [e]) if *e <= 1 => Self::Enable { guard, on: *e == 1 },
                _ => return Err(m),
            },
            0x03 => match g()? {
                (guard, []) => Self::Reset { guard },
                _ => return Err(m),
            },
            0x07 => match g()? {
                (guard, []) => Self::Release { guard },
                _ => return Err(m),
            },
            0x08 => match g()? {
                (guard, []) => Self::Heartbeat { guard },
                _ => return Err(m),
            },
            0x10 => {
                let (guard, v) = g()?;
                Self::ConfigBegin { guard, len: le2(v).ok_or(m)? }
            }
            0x04 if rest.is_empty() => Self::GetStatus,
            0x05 => Self::Telemetry { decimation: le2(rest).ok_or(m)? },
            0x06 => Self::Claim { nonce: le2(rest).ok_or(m)? },
            0x11 => match rest {
                [a, b, data @ ..] if !data.is_empty() && data.len() <= CHUNK => {
                    let mut d = [0u8; CHUNK];
                    for (o, i) in d.iter_mut().zip(data) {
                        *o = *i;
                    }
                    Self::ConfigData { offset: u16::from_le_bytes([*a, *b]), len: data.len() as u8, data: d }
                }
                _ => return Err(m),
            },
            0x12 => Self::ConfigCommit { crc: u32::from_le_bytes(le4(rest).ok_or(m)?) },
            0x13 if rest.is_empty() => Self::ConfigQuery,
            0x14 if rest.is_empty() => Self::Limits,
            0x04 | 0x13 | 0x14 => return Err(m),
            _ => return Err(Nack::Unknown),
        })
    }

    /// Encode into `out`; returns the frame length (0 for a set-torque reference that no
    /// frame can carry: see [`quantise_reference`]).
    pub fn encode(&self, out: &mut [u8; FRAME]) -> usize {
        let mut w = Writer { out, n: 0 };
        w.put(&[self.code()]);
        if let Some(g) = self.guard() {
            w.put(&g.tag().to_le_bytes());
            w.put(&g.deadline_ms.to_le_bytes());
        }
        match *self {
            Self::SetTorque { reference, .. } => match i24_of(reference) {
                Some(milli) => w.put(milli.to_le_bytes().get(..3).unwrap_or(&[])),
                None => return 0,
            },
            Self::Enable { on, .. } => w.put(&[u8::from(on)]),
            Self::Reset { .. }
            | Self::Release { .. }
            | Self::Heartbeat { .. }
            | Self::GetStatus
            | Self::ConfigQuery
            | Self::Limits => {}
            Self::Telemetry { decimation } => w.put(&decimation.to_le_bytes()),
            Self::Claim { nonce } => w.put(&nonce.to_le_bytes()),
            Self::ConfigBegin { len, .. } => w.put(&len.to_le_bytes()),
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
            Self::Ack { code, tag, now_ms } => {
                w.put(&[0x82, code]);
                w.put(&tag.to_le_bytes());
                w.put(&now_ms.to_le_bytes());
            }
            Self::Nack { code, why, tag, now_ms } => {
                w.put(&[0x83, code, why as u8]);
                w.put(&tag.to_le_bytes());
                w.put(&now_ms.to_le_bytes());
            }
            Self::PageCrc(crc) => {
                w.put(&[0x84]);
                w.put(&crc.to_le_bytes());
            }
            Self::Session { nonce, tag, now_ms } => {
                w.put(&[0x85]);
                w.put(&nonce.to_le_bytes());
                w.put(&tag.to_le_bytes());
                w.put(&now_ms.to_le_bytes());
            }
            Self::Limits { reference_max, control_hz } => {
                w.put(&[0x86]);
                w.put(&reference_max.to_le_bytes());
                w.put(&control_hz.to_le_bytes());
            }
        }
        w.n
    }

    /// Decode a reply (host side). A nack with a reason this build does not know is no
    /// reply (`None`), never another reason.
    pub fn decode(frame: &[u8]) -> Option<Self> {
        let w = |a: u8, b: u8| u16::from_le_bytes([a, b]);
        Some(match *frame {
            [0x81, mode, fault, overruns, t0, t1, t2, t3] => {
                Self::Status { mode, fault, overruns, torque_est: f32::from_le_bytes([t0, t1, t2, t3]) }
            }
            [0x82, code, t0, t1, n0, n1] => Self::Ack { code, tag: w(t0, t1), now_ms: w(n0, n1) },
            [0x83, code, why, t0, t1, n0, n1] => {
                Self::Nack { code, why: Nack::from_code(why)?, tag: w(t0, t1), now_ms: w(n0, n1) }
            }
            [0x84, a, b, c, d] => Self::PageCrc(u32::from_le_bytes([a, b, c, d])),
            [0x85, a, b, t0, t1, n0, n1] => Self::Session { nonce: w(a, b), tag: w(t0, t1), now_ms: w(n0, n1) },
            [0x86, a, b, c, d, h0, h1] => {
                Self::Limits { reference_max: f32::from_le_bytes([a, b, c, d]), control_hz: w(h0, h1) }
            }
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
