//! The per-sample control step the firmware calls from its ADC interrupt (and `hil-sim
//! loop` calls against the simulated clutch): the only implementation of the loop.
//!
//! Shape after quartiq's idsp/stabilizer: immutable [`ControlStep`] (the torque model and
//! its rate estimator), plain-data [`ControlState`], settings passed in as a
//! `&ValidatedConfig` each call so a new configuration is swapped in between two samples
//! by replacing a `Copy` value. [`ControlStep::step`] cannot fail, allocates nothing and
//! never emits NaN: every output field is finite for any input.

use super::calibration::{counts_to_units, CalibResult, CalibState, Calibration};
use super::config::{LoopMode, Scrub, ValidatedConfig};
use super::feedforward::{invert, static_output, StaticMap};
use super::pi::{clamp, Pi, PiState};
use super::pwm::{duty, Demag, DemagState};
use super::supervisor::{check, FaultCode, Observation, SupState};
use crate::rate::RateParams;
use crate::{Estimator, EstimatorState, Model, ParamError, Sample};

/// Operating mode.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Mode {
    /// Fresh state; the next enabled sample starts the calibration.
    #[default]
    Init,
    /// Bridge off, averaging the zero-current offsets.
    Calibrating,
    /// Loop closed.
    Running,
    /// `enable` is false: bridge off.
    Disabled,
    /// Latched fault: bridge off until `reset`.
    Fault(FaultCode),
}

/// One sample as the firmware has it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControlInput {
    /// Hall sensor and coil-current ADC counts (12-bit).
    pub hall: u16,
    pub current: u16,
    /// Bridge supply, V.
    pub supply_v: f32,
    /// Torque reference (N·m), or coil current (A) in [`LoopMode::Current`].
    pub reference: f32,
    /// Fluid/housing temperature, °C (NaN when there is no sensor).
    pub temperature: f32,
    /// The previous step missed its deadline.
    pub overrun: bool,
    /// Drive allowed; false puts the bridge off without a fault.
    pub enable: bool,
    /// Clear a latched fault (back to `Init`, which recalibrates).
    pub reset: bool,
}

impl ControlInput {
    /// An enabled sample with no temperature sensor and no overrun.
    pub const fn new(hall: u16, current: u16, supply_v: f32, reference: f32) -> Self {
        Self { hall, current, supply_v, reference, temperature: f32::NAN, overrun: false, enable: true, reset: false }
    }
}

/// Status bits of [`ControlOutput::flags`].
pub mod flags {
    /// The estimator held its output (non-finite model output or input).
    pub const ESTIMATE_HELD: u8 = 1 << 0;
    /// The reference was non-finite (0 used) or beyond its limit.
    pub const REFERENCE_LIMITED: u8 = 1 << 1;
    /// The demagnetising pulse drives the bridge.
    pub const DEMAG: u8 = 1 << 2;
    /// The voltage command hit the duty limit.
    pub const SATURATED: u8 = 1 << 3;
}

/// What the step returns. Every number is finite.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ControlOutput {
    /// Duty in `[−1, 1]` (sign = bridge diagonal), 0 when `pwm_enable` is false.
    pub duty: f32,
    /// Timer compare value for `duty`.
    pub compare: i32,
    /// False: all bridge switches off (safe state).
    pub pwm_enable: bool,
    /// Hall flux density, T; coil current, A.
    pub b: f32,
    pub current: f32,
    /// Torque estimate, N·m.
    pub torque_est: f32,
    /// Current reference, A; voltage command, V.
    pub i_ref: f32,
    pub v_cmd: f32,
    pub mode: Mode,
    pub fault: FaultCode,
    pub flags: u8,
}

/// Everything that changes from sample to sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ControlState<S> {
    pub mode: Mode,
    pub est: EstimatorState<S>,
    pub calib: CalibState,
    pub calibrated: bool,
    pub hall_offset: f32,
    pub current_offset: f32,
    pub pi_t: PiState,
    pub pi_i: PiState,
    pub sup: SupState,
    pub demag: DemagState,
    pub scrub: Scrub,
    /// Voltage commanded on the previous sample, V.
    pub last_v: f32,
    /// Previous feed-forward flux density (Newton start), T, and current, A.
    pub b_star: f32,
    pub i_ff: f32,
}

/// Immutable part: the torque model with its rate estimator.
#[derive(Clone, Copy, Debug)]
pub struct ControlStep<M: Model> {
    pub est: Estimator<M>,
}

fn finite_or(x: f32, alt: f32) -> f32 {
    if x.is_finite() {
        x
    } else {
        alt
    }
}

impl<M: Model> ControlStep<M> {
    /// Pair a model with its rate estimator (both for the configuration's `dt`).
    pub fn new(model: M, rate: RateParams) -> Result<Self, ParamError> {
        Ok(Self { est: Estimator::new(model, rate)? })
    }

    /// A fresh state (mode `Init`).
    pub fn state(&self) -> ControlState<M::State> {
        ControlState::default()
    }

    /// Process one sample. See the module documentation.
    pub fn step(&self, cfg: &ValidatedConfig, s: &mut ControlState<M::State>, x: ControlInput) -> ControlOutput {
        let c = cfg.get();
        let crc_ok = s.scrub.step(cfg);
        if !s.calibrated {
            s.hall_offset = c.hall_offset;
            s.current_offset = c.current_offset;
        }
        let b = counts_to_units(x.hall, s.hall_offset, c.hall_gain);
        let i = counts_to_units(x.current, s.current_offset, c.current_gain);
        let mut out = ControlOutput { b, current: i, torque_est: s.est.last, ..Default::default() };
        let dt_ok = crate::math::abs(c.dt - self.est.model.dt()) <= 1e-6 * c.dt;
        let early = if crc_ok == Some(false) {
            Some(FaultCode::ConfigCrc)
        } else if !dt_ok {
            Some(FaultCode::ConfigMismatch)
        } else {
            None
        };
        if let (Some(code), false) = (early, matches!(s.mode, Mode::Fault(_))) {
            return self.trip(s, out, code);
        }
        match s.mode {
            Mode::Fault(code) => {
                if x.reset {
                    *s = ControlState::default();
                    out.mode = s.mode;
                    return out;
                }
                out.mode = s.mode;
                out.fault = code;
                return out;
            }
            Mode::Init | Mode::Disabled if !x.enable => {
                s.mode = Mode::Disabled;
                s.last_v = 0.0;
                out.mode = s.mode;
                return out;
            }
            Mode::Init | Mode::Disabled => {
                s.mode = if s.calibrated { Mode::Running } else { Mode::Calibrating };
                s.calib = CalibState::default();
                out.mode = s.mode;
                return out;
            }
            Mode::Calibrating | Mode::Running if !x.enable => {
                s.mode = Mode::Disabled;
                s.pi_i = PiState::default();
                s.pi_t = PiState::default();
                s.last_v = 0.0;
                out.mode = s.mode;
                return out;
            }
            Mode::Calibrating => {
                let obs =
                    Observation { hall: x.hall, b, i, supply_v: x.supply_v, running: false, ..Default::default() };
                let code = check(c, &mut s.sup, &obs);
                if code != FaultCode::None {
                    return self.trip(s, out, code);
                }
                let cal = Calibration {
                    samples: c.calib_samples as u16,
                    max_spread: c.calib_max_spread as u16,
                    nominal_hall: c.hall_offset,
                    nominal_current: c.current_offset,
                    max_offset_error: c.calib_max_offset_error,
                };
                match cal.step(&mut s.calib, x.hall, x.current) {
                    CalibResult::Pending => {}
                    CalibResult::Failed => return self.trip(s, out, FaultCode::CalibrationFailed),
                    CalibResult::Done { hall_offset, current_offset } => {
                        s.hall_offset = hall_offset;
                        s.current_offset = current_offset;
                        s.calibrated = true;
                        s.mode = Mode::Running;
                    }
                }
                out.mode = s.mode;
                return out;
            }
            Mode::Running => {}
        }
        self.run(cfg, s, x, out, crc_ok)
    }

    fn trip(&self, s: &mut ControlState<M::State>, mut out: ControlOutput, code: FaultCode) -> ControlOutput {
        s.mode = Mode::Fault(code);
        s.last_v = 0.0;
        out.mode = s.mode;
        out.fault = code;
        out.duty = 0.0;
        out.compare = 0;
        out.pwm_enable = false;
        out
    }

    fn run(
        &self,
        cfg: &ValidatedConfig,
        s: &mut ControlState<M::State>,
        x: ControlInput,
        mut out: ControlOutput,
        crc_ok: Option<bool>,
    ) -> ControlOutput {
        let c = cfg.get();
        let (b, i) = (out.b, out.current);
        let est = self.est.step(&mut s.est, Sample::new(b).with_command(i));
        let obs = Observation {
            hall: x.hall,
            b,
            i,
            supply_v: x.supply_v,
            v_applied: s.last_v,
            model_bad: !est.flags.ok(),
            overrun: x.overrun,
            crc_ok,
            running: true,
        };
        let code = check(c, &mut s.sup, &obs);
        if code != FaultCode::None {
            return self.trip(s, out, code);
        }
        if !est.flags.ok() {
            out.flags |= flags::ESTIMATE_HELD;
        }
        // Temperature compensation of the estimate (first order, fluid datasheet slope).
        let scale = if c.temp_coeff != 0.0 && x.temperature.is_finite() {
            clamp(1.0 + c.temp_coeff * (x.temperature - c.temp_ref), 0.5, 1.5)
        } else {
            1.0
        };
        let t_est = finite_or(est.y * scale, 0.0);
        out.torque_est = t_est;
        let lim = if c.mode == LoopMode::Current { c.i_max } else { c.torque_max };
        let r = clamp(finite_or(x.reference, 0.0), -lim, lim);
        if r != x.reference {
            out.flags |= flags::REFERENCE_LIMITED;
        }
        let model = &self.est.model;
        let i_ref = match c.mode {
            LoopMode::Torque => {
                let t_static = |bb: f32| finite_or(static_output(model, &s.est.model, bb, i) * scale, 0.0);
                let t0 = t_static(0.0);
                let r_eff = if r > t0 { r } else { t0 };
                let start = clamp(finite_or(s.b_star, 0.0), 0.0, c.b_max);
                // One Newton step per sample from the last solution: the reference moves
                // little in one period, so this tracks the root (bounded work per sample).
                let b_star = invert(t_static, r_eff, start, 0.0, c.b_max, 1, 1e-3 * c.b_max);
                s.b_star = b_star;
                let i_ff = b_star / c.b_per_amp;
                let lead = c.ff_lead_s * (i_ff - s.i_ff) / c.dt;
                s.i_ff = i_ff;
                let pi = Pi::new(c.kp_t, c.ki_t, c.dt, 0.0, c.i_max);
                pi.step(&mut s.pi_t, r_eff - t_est, clamp(i_ff + lead, 0.0, c.i_max))
            }
            LoopMode::OpenLoopTorque => StaticMap { a: c.map }.current(r, c.i_max),
            LoopMode::Current => r,
        };
        let supply = finite_or(x.supply_v, 0.0);
        let v_lim = c.duty_max * if supply > 0.0 { supply } else { 0.0 };
        let pi_i = Pi::new(c.kp_i, c.ki_i, c.dt, -v_lim, v_lim);
        let demag = Demag { duty: c.demag_duty, samples: c.demag_samples as u16, threshold: c.demag_threshold };
        let (v, d) = match demag.step(&mut s.demag, r, i) {
            Some(d) => {
                out.flags |= flags::DEMAG;
                s.pi_i = PiState::default();
                s.pi_t = PiState::default();
                (d * x.supply_v, d)
            }
            None => {
                let v = pi_i.step(&mut s.pi_i, i_ref - i, c.coil_r * i_ref);
                if crate::math::abs(v) >= v_lim {
                    out.flags |= flags::SATURATED;
                }
                (v, v / x.supply_v)
            }
        };
        let (d, compare) = duty(d * x.supply_v, x.supply_v, c.duty_max, c.pwm_counts);
        s.last_v = finite_or(v, 0.0);
        out.i_ref = finite_or(i_ref, 0.0);
        out.v_cmd = s.last_v;
        out.duty = d;
        out.compare = compare;
        out.pwm_enable = true;
        out.mode = s.mode;
        out
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use super::*;
    use crate::control::ControlConfig;
    use crate::models::algebraic::Algebraic;
    use proptest::prelude::*;

    const DT: f32 = 1e-4;

    fn setup(mode: LoopMode) -> (ControlStep<Algebraic>, ValidatedConfig) {
        let m = Algebraic::new(20.0, -0.05, -10.0, 0.8, DT).unwrap();
        let step = ControlStep::new(m, RateParams::filtered(DT, 200.0).unwrap()).unwrap();
        let cfg = ControlConfig { mode, calib_samples: 10.0, ..ControlConfig::defaults(DT) };
        (step, cfg.validate().unwrap())
    }

    fn all_finite(o: &ControlOutput) -> bool {
        [o.duty, o.b, o.current, o.torque_est, o.i_ref, o.v_cmd].iter().all(|v| v.is_finite())
            && (-1.0..=1.0).contains(&o.duty)
    }

    #[test]
    fn calibrates_then_runs_and_drives_current_toward_its_reference() {
        let (step, cfg) = setup(LoopMode::Current);
        let mut s = step.state();
        for k in 0..11u16 {
            let o = step.step(&cfg, &mut s, ControlInput::new(2050 + k % 2, 2047, 24.0, 1.0));
            assert!(!o.pwm_enable, "bridge stays off while calibrating");
        }
        assert_eq!(s.mode, Mode::Running);
        assert!((s.hall_offset - 2050.5).abs() < 0.6, "{}", s.hall_offset);
        // A simple RL coil integrated here: the current loop pulls i toward 1 A.
        let (r, l) = (4.0f32, 0.02f32);
        let mut i = 0.0f32;
        for k in 0..2000u16 {
            let counts = (2047.0 + i / cfg.get().current_gain).round() as u16;
            let o = step.step(&cfg, &mut s, ControlInput::new(2050 + (i * 100.0) as u16 + k % 2, counts, 24.0, 1.0));
            assert!(o.pwm_enable && all_finite(&o), "{o:?}");
            i += DT * (o.duty * 24.0 - r * i) / l;
        }
        assert!((i - 1.0).abs() < 0.02, "current {i}");
    }

    #[test]
    fn fault_latches_until_reset() {
        let (step, cfg) = setup(LoopMode::Torque);
        let mut s = step.state();
        for _ in 0..12 {
            step.step(&cfg, &mut s, ControlInput::new(2048, 2048, 24.0, 2.0));
        }
        for _ in 0..3 {
            step.step(&cfg, &mut s, ControlInput::new(4095, 2048, 24.0, 2.0));
        }
        assert_eq!(s.mode, Mode::Fault(FaultCode::HallOpen));
        let o = step.step(&cfg, &mut s, ControlInput::new(2048, 2048, 24.0, 2.0));
        assert_eq!((o.pwm_enable, o.duty, o.fault), (false, 0.0, FaultCode::HallOpen));
        let o = step.step(&cfg, &mut s, ControlInput { reset: true, ..ControlInput::new(2048, 2048, 24.0, 0.0) });
        assert_eq!(o.mode, Mode::Init);
    }

    #[test]
    fn corrupted_config_trips_within_two_scrub_passes() {
        // Current mode at 0 A: nothing else can trip while the coil is not simulated.
        let (step, mut cfg) = setup(LoopMode::Current);
        let mut s = step.state();
        let input = |k: u16| ControlInput::new(2048 + k % 3, 2048 + k % 2, 24.0, 0.0);
        for k in 0..20 {
            step.step(&cfg, &mut s, input(k));
        }
        assert_eq!(s.mode, Mode::Running);
        cfg.inject_bit_flip(700);
        let passes = super::super::config::WORDS.div_ceil(super::super::config::SCRUB_WORDS);
        let tripped =
            (0..2 * passes).map(|k| step.step(&cfg, &mut s, input(k as u16))).any(|o| o.fault == FaultCode::ConfigCrc);
        assert!(tripped);
    }

    #[test]
    fn dt_mismatch_is_a_fault() {
        let (step, _) = setup(LoopMode::Torque);
        let cfg = ControlConfig { dt: 2e-4, ..ControlConfig::defaults(2e-4) }.validate().unwrap();
        let mut s = step.state();
        let o = step.step(&cfg, &mut s, ControlInput::new(2048, 2048, 24.0, 2.0));
        assert_eq!(o.fault, FaultCode::ConfigMismatch);
    }

    fn any_input() -> impl Strategy<Value = ControlInput> {
        let f = prop_oneof![any::<f32>(), Just(f32::NAN), Just(f32::INFINITY), Just(f32::NEG_INFINITY), -30.0f32..30.0];
        (any::<u16>(), any::<u16>(), f.clone(), f.clone(), f, any::<[bool; 3]>()).prop_map(
            |(hall, current, supply_v, reference, temperature, [overrun, enable, reset])| ControlInput {
                hall: hall % 4096,
                current: current % 4096,
                supply_v,
                reference,
                temperature,
                overrun,
                enable: enable || hall % 7 != 0,
                reset: reset && hall % 5 == 0,
            },
        )
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        #[test]
        fn never_panics_and_never_emits_nan(
            inputs in proptest::collection::vec(any_input(), 1..400),
            mode in prop_oneof![Just(LoopMode::Torque), Just(LoopMode::OpenLoopTorque), Just(LoopMode::Current)],
            temp_coeff in -0.01f32..0.01,
        ) {
            let (step, _) = setup(mode);
            let cfg = ControlConfig { mode, temp_coeff, calib_samples: 5.0, calib_max_spread: 4095.0,
                calib_max_offset_error: 4095.0, demag_samples: 5.0, ..ControlConfig::defaults(DT) }
                .validate().unwrap();
            let mut s = step.state();
            for x in inputs {
                let o = step.step(&cfg, &mut s, x);
                prop_assert!(all_finite(&o), "{:?} -> {:?}", x, o);
                if !o.pwm_enable {
                    prop_assert_eq!(o.duty, 0.0);
                }
                if let Mode::Fault(_) = o.mode {
                    prop_assert!(!o.pwm_enable);
                }
            }
        }
    }
}
