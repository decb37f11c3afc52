//! Plausibility checks and the fault codes. Every check counts consecutive (or recent)
//! violations so one noisy sample does not trip, and every fault the step latches ends in
//! the safe state: PWM off, bridge high-impedance, the coil current decaying through the
//! freewheeling diodes against the supply. An MR clutch without field transmits only its
//! small viscous drag (the safe state of a collaborative-robot joint, seed 000 §1).

use super::config::ControlConfig;

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
    /// The running CRC of the configuration does not match.
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
}

impl FaultCode {
    /// Numeric code.
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
        }
    }
}

/// What the supervisor sees each sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Observation {
    pub hall: u16,
    /// Hall flux density, T.
    pub b: f32,
    /// Coil current, A.
    pub i: f32,
    /// Supply voltage, V.
    pub supply_v: f32,
    /// Voltage commanded on the previous sample, V.
    pub v_applied: f32,
    /// The estimator held its output this sample (non-finite model output or input).
    pub model_bad: bool,
    /// The firmware reports the previous step missed its deadline.
    pub overrun: bool,
    /// Result of the running configuration CRC, when a pass ended this sample.
    pub crc_ok: Option<bool>,
    /// Loop running (the coil may carry current); otherwise only the sensor-independent
    /// checks and the rails apply.
    pub running: bool,
}

/// Counters of the checks.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SupState {
    pub rail_hi: u16,
    pub rail_lo: u16,
    pub over: u16,
    pub supply_lo: u16,
    pub supply_hi: u16,
    pub model: u16,
    pub overrun: u16,
    pub stuck: u16,
    pub open: u16,
    pub band: u16,
    /// Slew violations of the last 8 samples, one bit each, and how many are set.
    pub slew_hist: u8,
    pub slew_n: u8,
    /// Last Hall change that exceeded the slew limit, T.
    pub last_jump: f32,
    pub last_hall: u16,
    pub last_b: f32,
    pub primed: bool,
}

#[inline]
fn count(c: &mut u16, cond: bool) -> u16 {
    *c = if cond { c.saturating_add(1) } else { 0 };
    *c
}

/// Run every check; the first that trips, in a fixed priority order, is returned.
#[inline(always)]
pub fn check(cfg: &ControlConfig, s: &mut SupState, o: &Observation) -> FaultCode {
    let abs = crate::math::abs;
    let hall = f32::from(o.hall);
    let supply_ok = o.supply_v.is_finite();
    let c_rail_hi = hall >= cfg.hall_rail_hi;
    let c_rail_lo = hall <= cfg.hall_rail_lo;
    let c_supply_lo = !supply_ok || o.supply_v < cfg.v_min;
    let c_supply_hi = supply_ok && o.supply_v > cfg.v_max;
    let c_over = !o.i.is_finite() || abs(o.i) > cfg.over_current;
    let c_model = o.running && o.model_bad;
    // Noise reverses direction; a real field change (even a collapse when the coil
    // opens) moves one way. A violation is a jump beyond the slew limit that reverses the
    // previous one.
    let db = o.b - s.last_b;
    let big = s.primed && abs(db) > cfg.b_slew_max;
    let slew = big && db * s.last_jump < 0.0;
    if big {
        s.last_jump = db;
    }
    let new = u8::from(slew && o.running);
    s.slew_n = s.slew_n.wrapping_add(new).wrapping_sub(s.slew_hist >> 7);
    s.slew_hist = (s.slew_hist << 1) | new;
    let noise = u32::from(s.slew_n) >= cfg.slew_count as u32;
    let frozen = s.primed && o.hall == s.last_hall && o.running;
    let c_open = o.running && abs(o.v_applied) > cfg.open_v && abs(o.i) < cfg.open_i;
    let c_band = o.running && cfg.b_band > 0.0 && abs(o.b - cfg.b_per_amp * o.i) > cfg.b_band;
    s.last_hall = o.hall;
    s.last_b = o.b;
    s.primed = true;
    let crc_bad = o.crc_ok == Some(false);
    let confirm = cfg.confirm_samples as u16;
    let rail_hi = count(&mut s.rail_hi, c_rail_hi) >= confirm;
    let rail_lo = count(&mut s.rail_lo, c_rail_lo) >= confirm;
    let supply_lo = count(&mut s.supply_lo, c_supply_lo) >= confirm;
    let supply_hi = count(&mut s.supply_hi, c_supply_hi) >= confirm;
    let over = count(&mut s.over, c_over) >= confirm;
    let model = count(&mut s.model, c_model) >= confirm;
    let overrun = count(&mut s.overrun, o.overrun) >= confirm;
    let stuck = cfg.stuck_samples > 0.0 && f32::from(count(&mut s.stuck, frozen)) >= cfg.stuck_samples;
    let open = f32::from(count(&mut s.open, c_open)) >= cfg.open_samples;
    let band = f32::from(count(&mut s.band, c_band)) >= cfg.band_samples;
    if crc_bad {
        FaultCode::ConfigCrc
    } else if rail_hi {
        FaultCode::HallOpen
    } else if rail_lo {
        FaultCode::HallShort
    } else if over {
        FaultCode::OverCurrent
    } else if supply_lo {
        FaultCode::SupplyLow
    } else if supply_hi {
        FaultCode::SupplyHigh
    } else if overrun {
        FaultCode::Overrun
    } else if model {
        FaultCode::ModelNonFinite
    } else if noise {
        FaultCode::HallNoise
    } else if stuck {
        FaultCode::HallStuck
    } else if open {
        FaultCode::CoilOpen
    } else if band {
        FaultCode::BImplausible
    } else {
        FaultCode::None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ok_obs(k: u16) -> Observation {
        Observation {
            hall: 2048 + k % 3,
            b: 0.1,
            i: 0.5,
            supply_v: 24.0,
            v_applied: 2.0,
            running: true,
            ..Default::default()
        }
    }

    fn run(cfg: &ControlConfig, f: impl Fn(u16) -> Observation) -> (FaultCode, u16) {
        let mut s = SupState::default();
        for k in 0..50u16 {
            check(cfg, &mut s, &ok_obs(k));
        }
        for k in 0..100u16 {
            let c = check(cfg, &mut s, &f(k));
            if c != FaultCode::None {
                return (c, k + 1);
            }
        }
        (FaultCode::None, 0)
    }

    #[test]
    fn each_check_trips_alone_and_healthy_does_not() {
        let cfg = ControlConfig::defaults(1e-4);
        assert_eq!(run(&cfg, ok_obs).0, FaultCode::None);
        assert_eq!(run(&cfg, |k| Observation { hall: 4095, ..ok_obs(k) }), (FaultCode::HallOpen, 3));
        assert_eq!(run(&cfg, |k| Observation { hall: 0, ..ok_obs(k) }), (FaultCode::HallShort, 3));
        assert_eq!(run(&cfg, |k| Observation { hall: 2100, ..ok_obs(k) }), (FaultCode::HallStuck, 13));
        let noisy = |k: u16| Observation { b: if k.is_multiple_of(2) { 0.3 } else { -0.2 }, ..ok_obs(k) };
        // The first jump has no earlier one to reverse: the third reversal is the 4th sample.
        assert_eq!(run(&cfg, noisy), (FaultCode::HallNoise, 4));
        // A one-way collapse of the field (coil opened) is not noise.
        let collapse = |k: u16| Observation { b: 0.1 - 0.05 * f32::from(k.min(2)), ..ok_obs(k) };
        assert_eq!(run(&cfg, collapse).0, FaultCode::None);
        assert_eq!(run(&cfg, |k| Observation { i: 0.0, v_applied: 10.0, ..ok_obs(k) }), (FaultCode::CoilOpen, 10));
        assert_eq!(run(&cfg, |k| Observation { i: 9.0, ..ok_obs(k) }), (FaultCode::OverCurrent, 3));
        assert_eq!(run(&cfg, |k| Observation { supply_v: 12.0, ..ok_obs(k) }), (FaultCode::SupplyLow, 3));
        assert_eq!(run(&cfg, |k| Observation { overrun: true, ..ok_obs(k) }), (FaultCode::Overrun, 3));
        assert_eq!(run(&cfg, |k| Observation { model_bad: true, ..ok_obs(k) }), (FaultCode::ModelNonFinite, 3));
        assert_eq!(run(&cfg, |k| Observation { crc_ok: Some(false), ..ok_obs(k) }), (FaultCode::ConfigCrc, 1));
        let banded = ControlConfig { b_band: 0.05, ..cfg };
        assert_eq!(run(&banded, |k| Observation { b: 0.5, ..ok_obs(k) }), (FaultCode::BImplausible, 10));
        assert_eq!(run(&banded, |k| Observation { i: 2.0, ..ok_obs(k) }), (FaultCode::BImplausible, 10));
    }
}
