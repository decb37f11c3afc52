//! Controller settings: validated once, protected by a CRC, swapped in atomically.
//!
//! [`ControlConfig`] is plain data; [`ControlConfig::validate`] checks every bound and
//! returns a [`ValidatedConfig`] that carries the CRC-32 (IEEE 802.3, reflected,
//! polynomial 0xEDB88320) of its byte encoding ([`ControlConfig::to_words`], each word
//! little-endian f32). The firmware stores [`ValidatedConfig::to_bytes`] in flash and
//! reads it back with [`ValidatedConfig::from_bytes`], which rejects a CRC mismatch.
//!
//! Validation also pre-computes everything the per-sample step needs in the form it needs
//! it ([`Coeffs`]: integral gains times `dt`, reciprocals, limits as integer counts, the
//! disabled checks as unreachable limits), so the step does no division by a setting and
//! no per-sample conversion of one. While running, the slow supervisor
//! ([`ControlStep::slow`](super::ControlStep::slow), about 1 kHz) re-computes a
//! fingerprint of the RAM copy ([`ValidatedConfig::verify`], [`fingerprint_step`]: rotate
//! and xor, which catches any single-bit upset at a fraction of the CRC's cost) and checks
//! the coefficients against the settings, and trips
//! [`FaultCode::ConfigCrc`](super::FaultCode::ConfigCrc) on a mismatch, so a corrupted
//! setting is caught within one slow period after the upset.

use crate::error::{check, time_step};
use crate::ParamError;

mod coeffs;
mod crc;

pub use coeffs::{Coeffs, SLOW_TIMEOUT_S};
pub use crc::{crc32_update, crc_words};

/// What the torque reference means and how the loop is closed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoopMode {
    /// Closed torque loop on the Hall-based torque estimate (the product).
    Torque,
    /// Baseline without B sensing: reference torque → current through the static map
    /// ([`ControlConfig::map`]), current loop only.
    OpenLoopTorque,
    /// The reference is a coil current in A (a current driver, used for recordings).
    Current,
}

impl LoopMode {
    const fn to_word(self) -> f32 {
        match self {
            Self::Torque => 0.0,
            Self::OpenLoopTorque => 1.0,
            Self::Current => 2.0,
        }
    }
    fn from_word(w: f32) -> Option<Self> {
        if w == 0.0 {
            Some(Self::Torque)
        } else if w == 1.0 {
            Some(Self::OpenLoopTorque)
        } else if w == 2.0 {
            Some(Self::Current)
        } else {
            None
        }
    }
}

/// Every setting of the control step. Units in the field docs; counts are 12-bit ADC counts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControlConfig {
    pub mode: LoopMode,
    /// Baseline static map `T = a₀ + a₁|i| + a₂i² + a₃|i|³` (N·m, A).
    pub map: [f32; 4],
    /// Sample period, s (must equal the model's).
    pub dt: f32,
    /// Hall sensor gain, T per count.
    pub hall_gain: f32,
    /// Nominal Hall offset, counts (replaced by the calibration).
    pub hall_offset: f32,
    /// Hall readings at or beyond these counts are a rail (open / shorted sensor).
    pub hall_rail_lo: f32,
    pub hall_rail_hi: f32,
    /// Coil current sense gain, A per count, and nominal offset, counts.
    pub current_gain: f32,
    pub current_offset: f32,
    /// Zero-current calibration: samples averaged, largest Hall spread (counts), largest
    /// distance of a measured offset from its nominal value (counts).
    pub calib_samples: f32,
    pub calib_max_spread: f32,
    pub calib_max_offset_error: f32,
    /// Coil resistance (Ω) for the voltage feed-forward `R·i_ref`.
    pub coil_r: f32,
    /// Static slope of the magnetic circuit, T per A (feed-forward `i = B*/slope` and the
    /// B-versus-current plausibility check).
    pub b_per_amp: f32,
    /// Largest |B| the feed-forward may ask for, T.
    pub b_max: f32,
    /// Current loop PI: V per A and V per (A·s).
    pub kp_i: f32,
    pub ki_i: f32,
    /// Torque loop PI: A per N·m and A per (N·m·s).
    pub kp_t: f32,
    pub ki_t: f32,
    /// Lead time of the current feed-forward, s (compensates the eddy-current lag).
    pub ff_lead_s: f32,
    /// Current reference limit, A; torque reference limit, N·m.
    pub i_max: f32,
    pub torque_max: f32,
    /// Largest |duty| and the PWM compare resolution (counts for duty 1).
    pub duty_max: f32,
    pub pwm_counts: f32,
    /// Torque estimate temperature coefficient, 1/K (0 disables), at `temp_ref` °C:
    /// `T̂ = T_model·(1 + temp_coeff·(θ − temp_ref))`.
    pub temp_coeff: f32,
    pub temp_ref: f32,
    /// Demagnetising pulse when the command falls below `demag_threshold` (N·m, or A in
    /// current mode) after exceeding it: duty `−demag_duty` for `demag_samples` samples.
    pub demag_duty: f32,
    pub demag_samples: f32,
    pub demag_threshold: f32,
    /// Supervisor: over-current trip, A.
    pub over_current: f32,
    /// Supply voltage window, V.
    pub v_min: f32,
    pub v_max: f32,
    /// Coil open: |applied voltage| above `open_v` (V) with |i| below `open_i` (A) for
    /// `open_samples` samples.
    pub open_v: f32,
    pub open_i: f32,
    pub open_samples: f32,
    /// Largest plausible Hall change per sample, T; `slew_count` jumps beyond it that
    /// reverse the previous jump, within 8 samples, trip the noise check.
    pub b_slew_max: f32,
    pub slew_count: f32,
    /// The Hall counts repeating unchanged this many times is a stuck sensor (0 disables).
    pub stuck_samples: f32,
    /// |B − b_per_amp·i| above `b_band` (T) for `band_samples` samples is implausible
    /// (0 disables).
    pub b_band: f32,
    pub band_samples: f32,
    /// Samples a rail, supply, over-current, model or overrun condition must persist.
    pub confirm_samples: f32,
}

/// Bytes of [`ValidatedConfig::to_bytes`]: the words and the CRC.
pub const BYTES: usize = 4 * WORDS + 4;

/// One word into the running fingerprint of the RAM copy: rotate, xor. Linear over GF(2)
/// with a bijective rotation, so any single flipped bit (and any odd number of flips in one
/// bit lane) changes the result; 2 instructions a word instead of the CRC's ~30.
#[inline(always)]
pub fn fingerprint_step(acc: u32, w: f32) -> u32 {
    acc.rotate_left(5) ^ w.to_bits()
}

macro_rules! encoding {
    ($($f:ident),+ $(,)?) => {
        /// Number of f32 words in the encoding (mode, 4 map coefficients, the scalars).
        pub const WORDS: usize = 5 + [$(stringify!($f)),+].len();

        impl ControlConfig {
            /// The encoding: mode, map, then every scalar in declaration order.
            pub fn to_words(&self) -> [f32; WORDS] {
                let [m0, m1, m2, m3] = self.map;
                [self.mode.to_word(), m0, m1, m2, m3, $(self.$f),+]
            }
            /// Word `i` of [`to_words`](Self::to_words) without building the array (the
            /// running check reads a few words per sample); 0 past the end.
            #[inline]
            pub fn word(&self, i: usize) -> f32 {
                const GET: [fn(&ControlConfig) -> f32; WORDS] = [
                    |c| c.mode.to_word(),
                    |c| c.map[0],
                    |c| c.map[1],
                    |c| c.map[2],
                    |c| c.map[3],
                    $(|c| c.$f),+
                ];
                match GET.get(i) {
                    Some(g) => g(self),
                    None => 0.0,
                }
            }
            /// Decode (no validation); `None` for an unknown mode word.
            pub fn from_words(w: [f32; WORDS]) -> Option<Self> {
                let [mode, m0, m1, m2, m3, $($f),+] = w;
                Some(Self { mode: LoopMode::from_word(mode)?, map: [m0, m1, m2, m3], $($f),+ })
            }
        }
    };
}

encoding!(
    dt,
    hall_gain,
    hall_offset,
    hall_rail_lo,
    hall_rail_hi,
    current_gain,
    current_offset,
    calib_samples,
    calib_max_spread,
    calib_max_offset_error,
    coil_r,
    b_per_amp,
    b_max,
    kp_i,
    ki_i,
    kp_t,
    ki_t,
    ff_lead_s,
    i_max,
    torque_max,
    duty_max,
    pwm_counts,
    temp_coeff,
    temp_ref,
    demag_duty,
    demag_samples,
    demag_threshold,
    over_current,
    v_min,
    v_max,
    open_v,
    open_i,
    open_samples,
    b_slew_max,
    slew_count,
    stuck_samples,
    b_band,
    band_samples,
    confirm_samples,
);

const INF: f32 = f32::INFINITY;

fn whole(name: &'static str, v: f32, max: f32) -> Result<f32, ParamError> {
    let v = check(name, v, 0.0, max)?;
    if v == libm::floorf(v) {
        Ok(v)
    } else {
        Err(ParamError::Constraint { what: "count settings must be whole numbers" })
    }
}

impl ControlConfig {
    /// Defaults for a 12-bit ADC (mid-scale offsets), 24 V bridge, 0–3 A coil, at `dt` s.
    /// Gains that depend on the clutch must still be set by the caller.
    pub fn defaults(dt: f32) -> Self {
        Self {
            mode: LoopMode::Torque,
            map: [0.0, 1.0, 0.0, 0.0],
            dt,
            hall_gain: 1.25 / 2048.0,
            hall_offset: 2048.0,
            hall_rail_lo: 16.0,
            hall_rail_hi: 4079.0,
            current_gain: 6.0 / 2048.0,
            current_offset: 2048.0,
            calib_samples: 1000.0,
            calib_max_spread: 40.0,
            calib_max_offset_error: 200.0,
            coil_r: 4.0,
            b_per_amp: 0.2,
            b_max: 0.8,
            kp_i: 30.0,
            ki_i: 6000.0,
            kp_t: 0.05,
            ki_t: 100.0,
            ff_lead_s: 0.0,
            i_max: 3.5,
            torque_max: 15.0,
            duty_max: 0.95,
            pwm_counts: 4250.0,
            temp_coeff: 0.0,
            temp_ref: 20.0,
            demag_duty: 0.5,
            demag_samples: 0.0,
            demag_threshold: 1.0,
            over_current: 4.5,
            v_min: 18.0,
            v_max: 30.0,
            open_v: 3.0,
            open_i: 0.05,
            open_samples: 10.0,
            b_slew_max: 0.02,
            slew_count: 3.0,
            stuck_samples: 12.0,
            b_band: 0.0,
            band_samples: 10.0,
            confirm_samples: 3.0,
        }
    }

    /// Check every bound and attach the CRC.
    pub fn validate(self) -> Result<ValidatedConfig, ParamError> {
        for (i, w) in self.to_words().into_iter().enumerate() {
            debug_assert_eq!(w.to_bits(), self.word(i).to_bits());
            if !w.is_finite() {
                return Err(ParamError::NotFinite { name: "config" });
            }
        }
        time_step(self.dt)?;
        check("hall_gain", self.hall_gain, 1e-9, 1.0)?;
        check("hall_offset", self.hall_offset, 0.0, 4095.0)?;
        check("hall_rail_lo", self.hall_rail_lo, 0.0, 4095.0)?;
        check("hall_rail_hi", self.hall_rail_hi, self.hall_rail_lo + 1.0, 4095.0)?;
        check("current_gain", self.current_gain, 1e-9, 1.0)?;
        check("current_offset", self.current_offset, 0.0, 4095.0)?;
        whole("calib_samples", self.calib_samples, 60000.0)?;
        check("calib_samples", self.calib_samples, 1.0, 60000.0)?;
        whole("calib_max_spread", self.calib_max_spread, 4095.0)?;
        check("calib_max_offset_error", self.calib_max_offset_error, 0.0, 4095.0)?;
        check("coil_r", self.coil_r, 1e-3, 1e3)?;
        check("b_per_amp", self.b_per_amp, 1e-6, 100.0)?;
        check("b_max", self.b_max, 1e-6, 10.0)?;
        check("kp_i", self.kp_i, 0.0, 1e6)?;
        check("ki_i", self.ki_i, 0.0, 1e9)?;
        check("kp_t", self.kp_t, 0.0, 1e3)?;
        check("ki_t", self.ki_t, 0.0, 1e6)?;
        check("ff_lead_s", self.ff_lead_s, 0.0, 1.0)?;
        check("i_max", self.i_max, 1e-3, 100.0)?;
        check("torque_max", self.torque_max, 1e-3, 1e4)?;
        check("duty_max", self.duty_max, 0.0, 1.0)?;
        whole("pwm_counts", self.pwm_counts, 65535.0)?;
        check("pwm_counts", self.pwm_counts, 1.0, 65535.0)?;
        check("temp_coeff", self.temp_coeff, -0.1, 0.1)?;
        check("temp_ref", self.temp_ref, -100.0, 300.0)?;
        check("demag_duty", self.demag_duty, 0.0, self.duty_max)?;
        whole("demag_samples", self.demag_samples, 60000.0)?;
        check("demag_threshold", self.demag_threshold, 0.0, INF)?;
        check("over_current", self.over_current, self.i_max, 1e3)?;
        check("v_min", self.v_min, 0.0, 1e3)?;
        check("v_max", self.v_max, self.v_min, 1e3)?;
        check("open_v", self.open_v, 0.0, 1e3)?;
        check("open_i", self.open_i, 0.0, 1e3)?;
        whole("open_samples", self.open_samples, 60000.0)?;
        check("b_slew_max", self.b_slew_max, 1e-9, INF)?;
        whole("slew_count", self.slew_count, 8.0)?;
        check("slew_count", self.slew_count, 1.0, 8.0)?;
        whole("stuck_samples", self.stuck_samples, 60000.0)?;
        check("b_band", self.b_band, 0.0, INF)?;
        whole("band_samples", self.band_samples, 60000.0)?;
        whole("confirm_samples", self.confirm_samples, 255.0)?;
        check("confirm_samples", self.confirm_samples, 1.0, 255.0)?;
        if self.v_min <= 0.0 {
            return Err(ParamError::Constraint { what: "v_min must be > 0 (duty = V/supply)" });
        }
        let words = self.to_words();
        let crc = crc_words(&words);
        let fingerprint = words.iter().fold(SCRUB_SEED, |a, w| fingerprint_step(a, *w));
        Ok(ValidatedConfig { cfg: self, k: Coeffs::new(&self), crc, fingerprint })
    }
}

/// A configuration that passed [`ControlConfig::validate`], with the CRC of its encoding
/// (stored with it) and the fingerprint the running check compares against.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ValidatedConfig {
    cfg: ControlConfig,
    k: Coeffs,
    crc: u32,
    fingerprint: u32,
}

/// Start value of the running fingerprint.
const SCRUB_SEED: u32 = 0x5A5A_5A5A;

/// Why stored configuration bytes were rejected.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ConfigError {
    /// The stored CRC does not match the bytes.
    CrcMismatch { stored: u32, computed: u32 },
    /// The bytes decode but a value is invalid.
    Invalid(ParamError),
}

impl core::fmt::Display for ConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::CrcMismatch { stored, computed } => {
                write!(f, "configuration CRC mismatch: stored {stored:#010x}, computed {computed:#010x}")
            }
            Self::Invalid(e) => write!(f, "invalid configuration: {e}"),
        }
    }
}

impl core::error::Error for ConfigError {}

impl ValidatedConfig {
    /// Same as [`ControlConfig::validate`].
    pub fn new(cfg: ControlConfig) -> Result<Self, ParamError> {
        cfg.validate()
    }
    /// The settings.
    #[inline]
    pub const fn get(&self) -> &ControlConfig {
        &self.cfg
    }
    /// The pre-computed coefficients of the per-sample step.
    #[inline(always)]
    pub const fn coeffs(&self) -> &Coeffs {
        &self.k
    }
    /// The running check of the RAM copy: the fingerprint of the settings' encoding
    /// matches the one taken at validation and the coefficients are the ones the
    /// settings give. False after any single-bit upset of either.
    pub fn verify(&self) -> bool {
        let mut acc = SCRUB_SEED;
        for i in 0..WORDS {
            acc = fingerprint_step(acc, self.cfg.word(i));
        }
        acc == self.fingerprint && Coeffs::new(&self.cfg) == self.k
    }
    /// CRC-32 of the encoding as validated.
    pub const fn crc(&self) -> u32 {
        self.crc
    }
    /// The words followed by the CRC, little-endian (for flash).
    pub fn to_bytes(&self) -> [u8; BYTES] {
        let mut out = [0u8; BYTES];
        let words = self.cfg.to_words();
        let crc = self.crc.to_le_bytes();
        let src = words.iter().flat_map(|w| w.to_le_bytes()).chain(crc);
        for (o, b) in out.iter_mut().zip(src) {
            *o = b;
        }
        out
    }
    /// Read back [`to_bytes`](Self::to_bytes): CRC first, then validation.
    pub fn from_bytes(bytes: &[u8; BYTES]) -> Result<Self, ConfigError> {
        let mut words = [0.0f32; WORDS];
        for (w, c) in words.iter_mut().zip(bytes.chunks_exact(4)) {
            if let [a, b, c, d] = *c {
                *w = f32::from_le_bytes([a, b, c, d]);
            }
        }
        let stored = match bytes.get(4 * WORDS..) {
            Some([a, b, c, d]) => u32::from_le_bytes([*a, *b, *c, *d]),
            _ => 0,
        };
        let computed = crc_words(&words);
        if stored != computed {
            return Err(ConfigError::CrcMismatch { stored, computed });
        }
        let cfg = ControlConfig::from_words(words)
            .ok_or(ConfigError::Invalid(ParamError::Constraint { what: "unknown loop mode" }))?;
        cfg.validate().map_err(ConfigError::Invalid)
    }
    /// Fault injection: flip one bit of the RAM copy (as a radiation upset or a stray
    /// write would) without updating the CRC. Bit `n` of the encoding after the mode
    /// word (taken modulo its length). Exists so tests and the simulator can prove the
    /// running check ([`verify`](Self::verify)); the firmware never calls it.
    pub fn inject_bit_flip(&mut self, n: u32) {
        let mut w = self.cfg.to_words();
        let bits = 32 * (WORDS as u32 - 1);
        let n = n % bits;
        if let Some(word) = w.get_mut(1 + (n / 32) as usize) {
            *word = f32::from_bits(word.to_bits() ^ (1 << (n % 32)));
        }
        if let Some(c) = ControlConfig::from_words(w) {
            self.cfg = c;
        }
    }
}

#[cfg(test)]
mod tests;
