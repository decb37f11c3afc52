//! Framing of the protocol on a byte stream (the UART link, and TCP for the virtual board):
//! each frame is `payload ‖ CRC-32(payload)` (little-endian, the configuration page's
//! CRC-32), COBS-encoded, then one `0x00` delimiter. A receiver resynchronises on the next
//! `0x00` after garbage or lost bytes; a damaged frame fails its CRC and is dropped whole,
//! so a command is never misread.

use crate::control::config::crc32_update;

/// Largest payload (a telemetry frame is the longest).
pub const MAX_PAYLOAD: usize = 40;
/// Largest encoded frame: payload, CRC, COBS overhead byte, delimiter.
pub const MAX_ENCODED: usize = MAX_PAYLOAD + 4 + 2;

/// Why a received frame was dropped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameError {
    /// More bytes than any frame before the delimiter.
    TooLong,
    /// Not valid COBS (a code byte pointing past the end).
    Cobs,
    /// Shorter than a CRC.
    Short,
    /// The CRC does not match the payload.
    Crc,
}

fn crc(bytes: &[u8]) -> u32 {
    !crc32_update(!0, bytes)
}

/// Encode `payload` into `out`; returns the number of bytes, delimiter included (0 when the
/// payload is longer than [`MAX_PAYLOAD`]).
pub fn encode(payload: &[u8], out: &mut [u8; MAX_ENCODED]) -> usize {
    if payload.len() > MAX_PAYLOAD {
        return 0;
    }
    let mut raw = [0u8; MAX_PAYLOAD + 4];
    let n = payload.len() + 4;
    for (o, i) in raw.iter_mut().zip(payload.iter().chain(crc(payload).to_le_bytes().iter())) {
        *o = *i;
    }
    let mut w = 1usize; // next write position
    let mut code_at = 0usize;
    let mut code = 1u8;
    for &b in raw.iter().take(n) {
        if b == 0 {
            set(out, code_at, code);
            code_at = w;
            w += 1;
            code = 1;
        } else {
            set(out, w, b);
            w += 1;
            code += 1;
        }
    }
    set(out, code_at, code);
    set(out, w, 0);
    w + 1
}

fn set(out: &mut [u8], at: usize, v: u8) {
    if let Some(o) = out.get_mut(at) {
        *o = v;
    }
}

/// Collects bytes from a stream into frames.
#[derive(Clone, Debug)]
pub struct Deframer {
    buf: [u8; MAX_ENCODED],
    len: usize,
    overflow: bool,
    out: [u8; MAX_ENCODED],
}

impl Default for Deframer {
    fn default() -> Self {
        Self { buf: [0; MAX_ENCODED], len: 0, overflow: false, out: [0; MAX_ENCODED] }
    }
}

impl Deframer {
    /// Take one byte; at a delimiter, the frame's payload (CRC checked and removed) or why
    /// it was dropped. Empty frames (two delimiters in a row) are skipped silently.
    pub fn push(&mut self, byte: u8) -> Option<Result<&[u8], FrameError>> {
        if byte != 0 {
            match self.buf.get_mut(self.len) {
                Some(slot) if !self.overflow => {
                    *slot = byte;
                    self.len += 1;
                }
                _ => self.overflow = true,
            }
            return None;
        }
        let (len, overflow) = (self.len, self.overflow);
        self.len = 0;
        self.overflow = false;
        if overflow {
            return Some(Err(FrameError::TooLong));
        }
        if len == 0 {
            return None;
        }
        Some(self.decode(len))
    }

    fn decode(&mut self, len: usize) -> Result<&[u8], FrameError> {
        let src = self.buf.get(..len).ok_or(FrameError::TooLong)?;
        let mut n = 0usize;
        let mut i = 0usize;
        while i < len {
            let code = usize::from(*src.get(i).ok_or(FrameError::Cobs)?);
            let block = src.get(i + 1..i + code).ok_or(FrameError::Cobs)?;
            let dst = self.out.get_mut(n..n + block.len()).ok_or(FrameError::TooLong)?;
            dst.copy_from_slice(block);
            n += block.len();
            i += code;
            if code < 0xFF && i < len {
                *self.out.get_mut(n).ok_or(FrameError::TooLong)? = 0;
                n += 1;
            }
        }
        if n < 4 {
            return Err(FrameError::Short);
        }
        let payload = self.out.get(..n - 4).ok_or(FrameError::Short)?;
        let tail = self.out.get(n - 4..n).ok_or(FrameError::Short)?;
        let want = u32::from_le_bytes(<[u8; 4]>::try_from(tail).map_err(|_| FrameError::Short)?);
        if crc(payload) != want {
            return Err(FrameError::Crc);
        }
        Ok(payload)
    }
}
