//! Plausibility checks and the fault codes. Every check counts consecutive (or recent)
//! violations so one noisy sample does not trip, and every fault the step latches ends in
//! the safe state: PWM off, bridge high-impedance, the coil current decaying through the
//! freewheeling diodes against the supply. An MR clutch without field transmits only its
//! small viscous drag (the safe state of a collaborative-robot joint, seed 000 §1).
//!
//! Two places, so the per-sample cost stays small:
//! - [`fast_any`], every sample in every active mode: what must act within a few samples
//!   (Hall at a rail, over-current, supply outside its window, overrun, model output held)
//!   as one combined test with one counter: any of them on every one of `confirm`
//!   consecutive samples trips (at least as sensitive as a counter per condition). The
//!   code, in priority order, is worked out only when it trips ([`fast_code`]).
//! - [`ControlStep::slow`](super::ControlStep::slow), about 1 kHz from a lower-priority
//!   task: the configuration fingerprint, the model/configuration time step, the
//!   temperature compensation, and the slow-developing checks (Hall noise, stuck Hall,
//!   coil open, B inconsistent with i). For those the per-sample step only records its raw
//!   sample (Hall and current counts, the voltage applied) in the [`SampleLog`], a few
//!   instructions; the slow pass replays the samples since its previous pass through
//!   [`running`], with the same counters and limits as when they ran every sample, and
//!   latches the first fault in [`SupState::slow_fault`]. The per-sample step trips on the
//!   next sample, and trips [`FaultCode::SupervisorStalled`] if the slow pass stops running.
//!
//! Fault latency of the slow-developing checks: their own sample count (as before) plus at
//! most one slow period (the pass that sees the count reached) plus one sample (the trip);
//! at 20 kHz with the 1 kHz pass, ≤ 20 samples (1 ms) more than when they were judged every
//! sample. A slow pass later than [`LOG_SAMPLES`] samples judges the last
//! [`LOG_SAMPLES`] only: the counters count observed samples and carry on across the gap,
//! so a persistent fault still trips.

use super::config::Coeffs;

/// Why the controller stopped. `code()` is the number the firmware reports.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(u8)]
pub enum FaultCode {
    #[default]
    None = 0,
    /// Hall output at the upper rail (open wire, pull-up).
    HallOpen = 1,
    /// Hall output at the lower rail (shorted to ground).
    HallShort = 2,
    /// Hall counts frozen.
    HallStuck = 3,
    /// Sample-to-sample Hall changes faster than the magnetic circuit can move.
    HallNoise = 4,
    /// Voltage applied but no coil current.
    CoilOpen = 5,
    /// Coil current beyond the trip level (shorted coil or driver fault).
    OverCurrent = 6,
    /// Supply below `v_min`.
    SupplyLow = 7,
    /// Supply above `v_max`.
    SupplyHigh = 8,
    /// The running check of the configuration (fingerprint, coefficients) failed.
    ConfigCrc = 9,
    /// The torque model produced NaN/Inf (or overflowed) on consecutive samples.
    ModelNonFinite = 10,
    /// The control step missed its deadline on consecutive samples.
    Overrun = 11,
    /// Zero-current calibration too noisy or offset out of its window.
    CalibrationFailed = 12,
    /// Hall reading inconsistent with the coil current.
    BImplausible = 13,
    /// The configuration's time step is not the model's.
    ConfigMismatch = 14,
    /// The slow supervisor (configuration check) has not run for
    /// [`SLOW_TIMEOUT_S`](super::config::SLOW_TIMEOUT_S).
    SupervisorStalled = 15,
}

impl FaultCode {
    /// Numeric code.
    /// Every code, in code order.
    pub const ALL: [Self; 16] = [
        Self::None,
        Self::HallOpen,
        Self::HallShort,
        Self::HallStuck,
        Self::HallNoise,
        Self::CoilOpen,
        Self::OverCurrent,
        Self::SupplyLow,
        Self::SupplyHigh,
        Self::ConfigCrc,
        Self::ModelNonFinite,
        Self::Overrun,
        Self::CalibrationFailed,
        Self::BImplausible,
        Self::ConfigMismatch,
        Self::SupervisorStalled,
    ];

    pub const fn code(self) -> u8 {
        self as u8
    }
    /// Identifier used in reports.
    pub const fn name(self) -> &'static str {
        match self {
            Self::None => "none",
            Self::HallOpen => "hall_open",
            Self::HallShort => "hall_short",
            Self::HallStuck => "hall_stuck",
            Self::HallNoise => "hall_noise",
            Self::CoilOpen => "coil_open",
            Self::OverCurrent => "over_current",
            Self::SupplyLow => "supply_low",
            Self::SupplyHigh => "supply_high",
            Self::ConfigCrc => "config_crc",
            Self::ModelNonFinite => "model_non_finite",
            Self::Overrun => "overrun",
            Self::CalibrationFailed => "calibration_failed",
            Self::BImplausible => "b_implausible",
            Self::ConfigMismatch => "config_mismatch",
            Self::SupervisorStalled => "supervisor_stalled",
        }
    }
}

/// Counters of the checks.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SupState {
    /// Consecutive samples with a fast condition.
    pub fast: u32,
    pub stuck: u32,
    pub open: u32,
    pub band: u32,
    /// Slew violations of the last 8 samples, one bit each, and how many are set.
    pub slew_hist: u8,
    pub slew_n: u8,
    /// Last Hall change that exceeded the slew limit, counts.
    pub last_jump: i32,
    pub last_hall: u16,
    /// What the last slow pass found (`None`: all well).
    pub slow_fault: FaultCode,
    /// Samples since the last slow pass, or [`SLOW_LATCHED`] and up when that pass found a
    /// fault: one compare with the timeout covers both.
    pub since_slow: u32,
    /// A slow pass has run since this state was reset (the loop does not start before).
    pub slow_seen: bool,
    /// `since_slow` on the sample that entered `Running`: the slow pass replays the log
    /// entries after it (entries before are not the running loop's).
    pub log_start: u32,
}

/// Entries of the [`SampleLog`] (a power of two): at 20 kHz, 3.2 ms of samples, so a
/// slow pass (1 kHz) may be 2.2 ms late before samples go unjudged.
pub const LOG_SAMPLES: usize = 64;

/// One running sample as the slow-developing checks need it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LogEntry {
    /// Hall counts (low half) and coil-current counts (high half).
    pub counts: u32,
    /// Voltage commanded on the previous sample, V.
    pub v_applied: f32,
}

/// Ring of the running samples since the last slow pass, written at index
/// `since_slow mod LOG_SAMPLES` by the per-sample step, replayed by the slow pass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleLog(pub [LogEntry; LOG_SAMPLES]);

impl Default for SampleLog {
    fn default() -> Self {
        Self([LogEntry::default(); LOG_SAMPLES])
    }
}

impl SampleLog {
    /// Record a running sample at position `n` (`since_slow` of that sample). Branch-free,
    /// no bounds check (the index is masked).
    #[inline(always)]
    pub fn record(&mut self, n: u32, hall: u16, current: u16, v_applied: f32) {
        if let Some(e) = self.0.get_mut(n as usize & (LOG_SAMPLES - 1)) {
            *e = LogEntry { counts: u32::from(hall) | (u32::from(current) << 16), v_applied };
        }
    }

    /// Replay the entries after `start` up to `end` (positions as [`record`](Self::record)
    /// got them; at most the last [`LOG_SAMPLES`]) through [`running`], converting the
    /// counts with the offsets (counts) and the gains of `k`. Returns the first fault found
    /// ([`running_code`]), or `None`.
    pub fn judge(&self, k: &Coeffs, s: &mut SupState, start: u32, end: u32, offsets: (f32, f32)) -> FaultCode {
        let first = start.max(end.saturating_sub(LOG_SAMPLES as u32)).wrapping_add(1);
        let mut n = first;
        while n <= end {
            if let Some(e) = self.0.get(n as usize & (LOG_SAMPLES - 1)) {
                let hall = (e.counts & 0xFFFF) as u16;
                let current = (e.counts >> 16) as u16;
                let b = super::calibration::counts_to_units(hall, offsets.0, k.hall_gain);
                let i = super::calibration::counts_to_units(current, offsets.1, k.current_gain);
                if running(k, s, hall, b, i, e.v_applied) {
                    return running_code(k, s);
                }
            }
            n = n.wrapping_add(1);
        }
        FaultCode::None
    }
}

/// [`SupState::since_slow`] after a slow pass that found a fault.
pub const SLOW_LATCHED: u32 = 1 << 31;

/// One sample's inputs of the fast checks.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Fast {
    /// Hall ADC counts.
    pub hall: u16,
    /// Coil current, A.
    pub i: f32,
    /// Supply, V (any value; NaN is out of the window).
    pub supply_v: f32,
    /// The previous step missed its deadline.
    pub overrun: bool,
    /// The estimator held its output this sample.
    pub model_bad: bool,
}

/// Whether any fast condition holds. NaN-proof (a NaN supply is outside the window); the
/// current is finite by construction (counts × gain).
#[inline(always)]
pub fn fast_any(k: &Coeffs, f: &Fast) -> bool {
    fast_any_with(k, f, supply_window(k, f.supply_v).1)
}

/// [`fast_any`] with the supply test already made (`supply_bad` from [`supply_window`], as
/// the step needs the limited supply anyway). Branch-free.
#[inline(always)]
pub fn fast_any_with(k: &Coeffs, f: &Fast, supply_bad: bool) -> bool {
    let rail = u32::from(f.hall).wrapping_sub(k.rail_base) >= k.rail_span;
    let over = crate::math::abs(f.i) > k.over_current;
    rail | over | supply_bad | f.overrun | f.model_bad
}

/// The supply `v` (V) limited to its window `[v_min, v_max]` (NaN → `v_min`), and whether
/// it was outside (a fast condition). Inside the window (the usual case) two compares.
#[inline(always)]
pub fn supply_window(k: &Coeffs, v: f32) -> (f32, bool) {
    if v >= k.v_min && v <= k.v_max {
        (v, false)
    } else {
        (super::pi::clamp(v, k.v_min, k.v_max), true)
    }
}

/// Count a fast condition; true when it has held `confirm` consecutive samples.
#[inline(always)]
pub fn confirm(k: &Coeffs, s: &mut SupState, any: bool) -> bool {
    s.fast = if any { s.fast.wrapping_add(1) } else { 0 };
    s.fast >= k.confirm
}

/// The fault code of a sample whose fast conditions tripped, in priority order (rail
/// high, rail low, over-current, supply low, supply high, overrun, model).
#[cold]
#[inline(never)]
pub fn fast_code(k: &Coeffs, f: &Fast) -> FaultCode {
    fast_code_inline(k, f)
}

/// [`fast_code`], inlined (for a caller that must not grow its stack).
#[inline(always)]
pub fn fast_code_inline(k: &Coeffs, f: &Fast) -> FaultCode {
    let hall = u32::from(f.hall);
    if hall >= k.rail_hi {
        FaultCode::HallOpen
    } else if hall.wrapping_sub(k.rail_base) >= k.rail_span {
        FaultCode::HallShort
    } else if crate::math::abs(f.i) > k.over_current {
        FaultCode::OverCurrent
    } else if f.supply_v.is_nan() || f.supply_v < k.v_min {
        FaultCode::SupplyLow
    } else if f.supply_v > k.v_max {
        FaultCode::SupplyHigh
    } else if f.overrun {
        FaultCode::Overrun
    } else {
        FaultCode::ModelNonFinite
    }
}

/// Start the slow-developing checks from this sample (on entering `Running`).
#[inline]
pub fn prime(s: &mut SupState, hall: u16) {
    s.log_start = s.since_slow;
    s.last_hall = hall;
    s.last_jump = 0;
    s.slew_hist = 0;
    s.slew_n = 0;
    s.stuck = 0;
    s.open = 0;
    s.band = 0;
}

#[inline(always)]
fn count(c: &mut u32, cond: bool) -> u32 {
    *c = if cond { c.wrapping_add(1) } else { 0 };
    *c
}

/// The slow-developing checks of one running sample (replayed by the slow pass from the
/// [`SampleLog`]): Hall `hall` (counts) and `b` (T),
/// coil current `i` (A), the voltage commanded on the previous sample `v_applied` (V).
/// True when one of them trips ([`running_code`] tells which).
#[inline(always)]
pub fn running(k: &Coeffs, s: &mut SupState, hall: u16, b: f32, i: f32, v_applied: f32) -> bool {
    let abs = crate::math::abs;
    // Noise reverses direction; a real field change (even a collapse when the coil
    // opens) moves one way. A violation is a jump beyond the slew limit that reverses the
    // previous one. In counts (ΔB = Δcounts·gain): integer compares.
    let d = i32::from(hall) - i32::from(s.last_hall);
    s.last_hall = hall;
    let big = d.unsigned_abs() > k.slew_counts;
    let slew = big && d * s.last_jump < 0;
    if big {
        s.last_jump = d;
    }
    let new = u8::from(slew);
    s.slew_n = s.slew_n.wrapping_add(new).wrapping_sub(s.slew_hist >> 7);
    s.slew_hist = (s.slew_hist << 1) | new;
    let noise = u32::from(s.slew_n) >= k.slew_n;
    let stuck = count(&mut s.stuck, d == 0) >= k.stuck_n;
    let open = count(&mut s.open, abs(v_applied) > k.open_v && abs(i) < k.open_i) >= k.open_n;
    let band = count(&mut s.band, abs(b - k.b_per_amp * i) > k.b_band) >= k.band_n;
    noise | stuck | open | band
}

/// Which slow-developing check tripped (after [`running`] returned true), in priority
/// order: noise, stuck, coil open, band.
#[cold]
#[inline(never)]
pub fn running_code(k: &Coeffs, s: &SupState) -> FaultCode {
    running_code_inline(k, s)
}

/// [`running_code`], inlined.
#[inline(always)]
pub fn running_code_inline(k: &Coeffs, s: &SupState) -> FaultCode {
    if u32::from(s.slew_n) >= k.slew_n {
        FaultCode::HallNoise
    } else if s.stuck >= k.stuck_n {
        FaultCode::HallStuck
    } else if s.open >= k.open_n {
        FaultCode::CoilOpen
    } else {
        FaultCode::BImplausible
    }
}

#[cfg(test)]
mod tests;
