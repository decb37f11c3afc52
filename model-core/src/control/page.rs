//! The configuration page in flash: model id and parameters, rate estimator, every control
//! setting (calibration, gains, limits), with a magic, a version and a CRC-32 over all of it.
//!
//! One encoder and one decoder, used by the firmware (reading its flash page, receiving a
//! page over the command interface) and by `hil-sim export` (writing a fitted parameter
//! set), so the two cannot drift apart. Layout, little-endian, [`PAGE_BYTES`] long:
//!
//! | offset | size | field |
//! | --- | --- | --- |
//! | 0 | 4 | magic `MRCC` (`0x4343_524D` as u32) |
//! | 4 | 2 | format version ([`VERSION`]) |
//! | 6 | 2 | `len`: bytes covered by the CRC (the CRC follows them) |
//! | 8 | 24 | model id, ASCII, zero-padded (`hil-sim models`) |
//! | 32 | 4 | rate estimator: 0 backward, 1 filtered, 2 Kalman (u32) |
//! | 36 | 4 | filtered: cut-off Hz; Kalman: q (f32) |
//! | 40 | 4 | Kalman: r (f32), else 0 |
//! | 44 | 4 | number of model parameters n (u32) |
//! | 48 | 4·[`WORDS`] | [`ControlConfig::to_words`] |
//! | 48 + 4·WORDS | 4·n | model parameters, `hil-sim models` order |
//! | `len` | 4 | CRC-32 (IEEE, as [`crc_words`](super::config::crc_words)) of bytes `0..len` |
//! | `len + 4` | … | `0xFF` (erased flash) |
//!
//! [`ConfigImage::decode`] checks the magic, version, lengths and CRC, then validates the
//! control settings; the model parameters are validated by the model's own `from_params`
//! ([`ConfigImage::model`]) before anything is swapped in.

use super::config::{crc32_update, ControlConfig, ValidatedConfig, WORDS};
use crate::rate::RateParams;
use crate::{Model, ParamError};

/// Size of the page (one 2 KiB flash page of the STM32G474 in dual-bank mode).
pub const PAGE_BYTES: usize = 2048;
/// `MRCC`.
pub const MAGIC: u32 = 0x4343_524D;
/// Format version.
pub const VERSION: u16 = 1;
/// Bytes of the model-id field.
pub const ID_BYTES: usize = 24;
const HEADER: usize = 48;
/// Most model parameters a page holds.
pub const MAX_PARAMS: usize = (PAGE_BYTES - HEADER - 4 * WORDS - 4) / 4;

/// The rate estimator, as stored.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RateSpec {
    Backward,
    /// First-order filtered difference, cut-off in Hz.
    Filtered {
        fc: f32,
    },
    /// Seed 002's Kalman filter: jerk intensity q, measurement variance r.
    Kalman {
        q: f32,
        r: f32,
    },
}

impl RateSpec {
    /// The estimator's coefficients at time step `dt`.
    pub fn build(self, dt: f32) -> Result<RateParams, ParamError> {
        match self {
            Self::Backward => RateParams::backward(dt),
            Self::Filtered { fc } => RateParams::filtered(dt, fc),
            Self::Kalman { q, r } => RateParams::kalman(dt, q, r),
        }
    }
}

/// Why a page was rejected.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PageError {
    /// Erased or foreign data.
    BadMagic,
    UnsupportedVersion(u16),
    /// `len`, the parameter count or the model id is out of range.
    Malformed(&'static str),
    CrcMismatch {
        stored: u32,
        computed: u32,
    },
    /// The control settings decode but fail validation.
    Invalid(ParamError),
    /// The page is for another model than the one asked for.
    WrongModel,
}

impl core::fmt::Display for PageError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::BadMagic => write!(f, "not a configuration page (bad magic)"),
            Self::UnsupportedVersion(v) => write!(f, "configuration page version {v} is not supported ({VERSION} is)"),
            Self::Malformed(what) => write!(f, "malformed configuration page: {what}"),
            Self::CrcMismatch { stored, computed } => {
                write!(f, "configuration page CRC mismatch: stored {stored:#010x}, computed {computed:#010x}")
            }
            Self::Invalid(e) => write!(f, "invalid control settings: {e}"),
            Self::WrongModel => write!(f, "the page is for another model"),
        }
    }
}

impl core::error::Error for PageError {}

/// Everything a page holds.
///
/// # Examples
///
/// ```
/// use model_core::control::{ConfigImage, ControlConfig, RateSpec};
/// use model_core::models::bouc_wen::{BoucWen, SEED000_AVERAGE};
///
/// let dt = 5e-5;
/// let control = ControlConfig { kp_t: 0.2, ..ControlConfig::defaults(dt) }.validate()?;
/// let rate = RateSpec::Kalman { q: 1e6, r: 1e-6 };
/// let image = ConfigImage::new("bouc_wen", &SEED000_AVERAGE, rate, control)?;
/// let page = image.encode(); // the bytes of the flash page
/// let back = ConfigImage::decode(&page)?;
/// assert_eq!(back, image);
/// // The firmware builds its model and rate estimator from the page.
/// let model: BoucWen = back.model()?;
/// let rate = back.rate.build(dt)?;
/// # let _ = (model, rate);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConfigImage {
    id: [u8; ID_BYTES],
    pub rate: RateSpec,
    pub control: ValidatedConfig,
    params: [f32; MAX_PARAMS],
    n_params: usize,
}

fn put(out: &mut [u8; PAGE_BYTES], at: usize, bytes: &[u8]) {
    if let Some(dst) = out.get_mut(at..at + bytes.len()) {
        dst.copy_from_slice(bytes);
    }
}

fn get4(b: &[u8], at: usize) -> [u8; 4] {
    match b.get(at..at + 4) {
        Some([a, b, c, d]) => [*a, *b, *c, *d],
        _ => [0; 4],
    }
}

fn crc(bytes: &[u8]) -> u32 {
    !crc32_update(!0, bytes)
}

impl ConfigImage {
    /// A page for model `id` with `params` (checked against the model by the caller, see
    /// [`ConfigImage::model`]).
    pub fn new(id: &str, params: &[f32], rate: RateSpec, control: ValidatedConfig) -> Result<Self, PageError> {
        if id.is_empty() || id.len() > ID_BYTES || !id.bytes().all(|b| b.is_ascii_graphic()) {
            return Err(PageError::Malformed("model id must be 1-24 printable ASCII characters"));
        }
        if params.len() > MAX_PARAMS {
            return Err(PageError::Malformed("too many model parameters for one page"));
        }
        if !params.iter().all(|p| p.is_finite()) {
            return Err(PageError::Invalid(ParamError::NotFinite { name: "model parameter" }));
        }
        let mut img = Self { id: [0; ID_BYTES], rate, control, params: [0.0; MAX_PARAMS], n_params: params.len() };
        for (d, s) in img.id.iter_mut().zip(id.bytes()) {
            *d = s;
        }
        for (d, s) in img.params.iter_mut().zip(params) {
            *d = *s;
        }
        Ok(img)
    }

    /// The model id.
    pub fn model_id(&self) -> &str {
        let n = self.id.iter().position(|b| *b == 0).unwrap_or(ID_BYTES);
        self.id.get(..n).and_then(|s| core::str::from_utf8(s).ok()).unwrap_or("")
    }

    /// The model parameters.
    pub fn params(&self) -> &[f32] {
        self.params.get(..self.n_params).unwrap_or(&[])
    }

    /// Build model `M` from the page (its id must be `M::ID`), validated by `from_params`
    /// at the control settings' time step.
    pub fn model<M: Model>(&self) -> Result<M, PageError> {
        if self.model_id() != M::ID {
            return Err(PageError::WrongModel);
        }
        M::from_params(self.params(), self.control.get().dt).map_err(PageError::Invalid)
    }

    /// The CRC-32 the page carries (over its header and words, as [`ConfigImage::encode`]
    /// writes it): what `export` prints and what the board reports for its running page.
    pub fn crc(&self) -> u32 {
        let bytes = self.encode();
        let len = usize::from(u16::from_le_bytes([bytes[6], bytes[7]]));
        bytes.get(len..len + 4).and_then(|b| <[u8; 4]>::try_from(b).ok()).map_or(0, u32::from_le_bytes)
    }

    /// The page bytes.
    pub fn encode(&self) -> [u8; PAGE_BYTES] {
        let mut out = [0xFFu8; PAGE_BYTES];
        let len = HEADER + 4 * WORDS + 4 * self.n_params;
        put(&mut out, 0, &MAGIC.to_le_bytes());
        put(&mut out, 4, &VERSION.to_le_bytes());
        put(&mut out, 6, &(len as u16).to_le_bytes());
        put(&mut out, 8, &self.id);
        let (kind, a, b) = match self.rate {
            RateSpec::Backward => (0u32, 0.0f32, 0.0f32),
            RateSpec::Filtered { fc } => (1, fc, 0.0),
            RateSpec::Kalman { q, r } => (2, q, r),
        };
        put(&mut out, 32, &kind.to_le_bytes());
        put(&mut out, 36, &a.to_le_bytes());
        put(&mut out, 40, &b.to_le_bytes());
        put(&mut out, 44, &(self.n_params as u32).to_le_bytes());
        for (i, w) in self.control.get().to_words().iter().enumerate() {
            put(&mut out, HEADER + 4 * i, &w.to_le_bytes());
        }
        for (i, p) in self.params().iter().enumerate() {
            put(&mut out, HEADER + 4 * WORDS + 4 * i, &p.to_le_bytes());
        }
        let c = crc(out.get(..len).unwrap_or(&[]));
        put(&mut out, len, &c.to_le_bytes());
        out
    }

    /// Read a page: magic, version, lengths, CRC, then the control settings' validation.
    pub fn decode(bytes: &[u8]) -> Result<Self, PageError> {
        if u32::from_le_bytes(get4(bytes, 0)) != MAGIC {
            return Err(PageError::BadMagic);
        }
        let [v0, v1, l0, l1] = get4(bytes, 4);
        let version = u16::from_le_bytes([v0, v1]);
        if version != VERSION {
            return Err(PageError::UnsupportedVersion(version));
        }
        let len = usize::from(u16::from_le_bytes([l0, l1]));
        let n = u32::from_le_bytes(get4(bytes, 44)) as usize;
        if n > MAX_PARAMS || len != HEADER + 4 * WORDS + 4 * n || len + 4 > bytes.len().min(PAGE_BYTES) {
            return Err(PageError::Malformed("length fields"));
        }
        let stored = u32::from_le_bytes(get4(bytes, len));
        let computed = crc(bytes.get(..len).unwrap_or(&[]));
        if stored != computed {
            return Err(PageError::CrcMismatch { stored, computed });
        }
        let f = |at: usize| f32::from_le_bytes(get4(bytes, at));
        let rate = match u32::from_le_bytes(get4(bytes, 32)) {
            0 => RateSpec::Backward,
            1 => RateSpec::Filtered { fc: f(36) },
            2 => RateSpec::Kalman { q: f(36), r: f(40) },
            _ => return Err(PageError::Malformed("unknown rate estimator")),
        };
        let mut words = [0.0f32; WORDS];
        for (i, w) in words.iter_mut().enumerate() {
            *w = f(HEADER + 4 * i);
        }
        let control = ControlConfig::from_words(words)
            .ok_or(PageError::Malformed("unknown loop mode"))?
            .validate()
            .map_err(PageError::Invalid)?;
        let mut params = [0.0f32; MAX_PARAMS];
        for (i, p) in params.iter_mut().take(n).enumerate() {
            *p = f(HEADER + 4 * WORDS + 4 * i);
        }
        let mut id = [0u8; ID_BYTES];
        for (d, s) in id.iter_mut().zip(bytes.iter().skip(8)) {
            *d = *s;
        }
        let img = Self { id, rate, control, params, n_params: n };
        if img.model_id().is_empty() {
            return Err(PageError::Malformed("empty model id"));
        }
        Ok(img)
    }
}

#[cfg(test)]
mod tests;
