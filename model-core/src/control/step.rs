//! The per-sample control step the firmware calls from its ADC interrupt (and `hil-sim
//! loop` calls against the simulated clutch): the only implementation of the loop.
//!
//! Shape after quartiq's idsp/stabilizer: immutable [`ControlStep`] (the torque model and
//! its rate estimator), plain-data [`ControlState`], settings passed in as a
//! `&ValidatedConfig` each call (its [`Coeffs`] pre-computed at validation) so a new
//! configuration is swapped in between two samples by replacing a `Copy` value.
//!
//! Two entry points:
//! - [`ControlStep::step`], every sample (20 kHz): cannot fail, allocates nothing and never
//!   emits NaN: every output field is finite for any input. Its hot path (loop closed)
//!   is straight-line code with no division by a setting and no model evaluation but the
//!   estimate; the other modes take a separate, equally bounded path. The current loop
//!   runs every sample; the torque loop at half the rate, in two phases on alternate
//!   samples (the feed-forward, then the PI), its current reference held in between.
//! - [`ControlStep::slow`], about 1 kHz from a lower-priority task: the checks that need
//!   not run every sample (configuration fingerprint and coefficients, model/configuration
//!   time step, and the slow-developing supervisor checks — Hall noise, stuck Hall, coil
//!   open, B/i band — replayed from the [`SampleLog`] the step writes, a few instructions
//!   a sample), the temperature compensation and the feed-forward's linearisation
//!   ([`Linear`]: operating point, static torque and slope). A fault it finds is latched and trips
//!   the next sample, so a slow-developing fault trips within its own sample count plus
//!   one slow period plus one sample (at 20 kHz with the 1 kHz pass: ≤ 21 samples later
//!   than when it was judged every sample); a step that sees no slow pass for
//!   [`SLOW_TIMEOUT_S`](super::config::SLOW_TIMEOUT_S) trips
//!   [`FaultCode::SupervisorStalled`], and the loop does not start before a first pass.

use super::calibration::{counts_to_units, CalibResult, CalibState, Calibration};
use super::config::{Coeffs, LoopMode, ValidatedConfig};
use super::feedforward::{static_output, Linear, StaticMap};
use super::pi::{clamp, step_limited, PiState};
use super::pwm::{quantise, Demag, DemagState};
use super::supervisor::{self, confirm, fast_any, fast_any_with, Fast, FaultCode, SampleLog, SupState, SLOW_LATCHED};
use crate::rate::RateParams;
use crate::{Estimator, EstimatorState, Model, ParamError};

/// Operating mode.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Mode {
    /// Fresh state; the next enabled sample after a first slow pass starts the calibration.
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
    /// The previous step missed its deadline.
    pub overrun: bool,
    /// Drive allowed; false puts the bridge off without a fault.
    pub enable: bool,
    /// Clear a latched fault (back to `Init`, which recalibrates).
    pub reset: bool,
}

impl ControlInput {
    /// An enabled sample with no overrun.
    pub const fn new(hall: u16, current: u16, supply_v: f32, reference: f32) -> Self {
        Self { hall, current, supply_v, reference, overrun: false, enable: true, reset: false }
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
    /// Zero-current offsets, counts.
    pub hall_offset: f32,
    pub current_offset: f32,
    pub pi_t: PiState,
    pub pi_i: PiState,
    pub sup: SupState,
    /// The running samples since the last slow pass, for its slow-developing checks.
    pub log: SampleLog,
    pub demag: DemagState,
    /// Voltage commanded on the previous sample, V.
    pub last_v: f32,
    /// The feed-forward map (set by the slow pass) and the reference (N·m, at least the
    /// torque floor) of the torque loop's last feed-forward phase: the lead's previous
    /// value, the PI phase's reference and where the slow pass moves the map's operating
    /// point.
    pub ff: Linear,
    pub r_last: f32,
    /// Torque loop: this sample is its PI phase (it alternates with the feed-forward
    /// phase), the feed-forward current of the last feed-forward phase (A) and the current
    /// reference of the last PI phase (A), held in between.
    pub pi_phase: bool,
    pub ff_i: f32,
    pub i_ref: f32,
    /// Temperature compensation factor of the estimate (1: none), set by the slow pass
    /// (which runs before the loop starts).
    pub temp_scale: f32,
    /// Coil current of the last running sample, A. The slow pass takes the model's static
    /// part there: its torque at B = 0 (the floor of the reachable torque, N·m) and the
    /// feed-forward map.
    pub last_i: f32,
    pub t_floor: f32,
}

impl<S: Default> ControlState<S> {
    /// Back to [`Default`] (mode `Init`), field by field: no state-sized temporary on the
    /// stack of the step. The sample log keeps its (unread) contents.
    #[inline(never)]
    pub fn reset(&mut self) {
        self.mode = Mode::Init;
        self.est = EstimatorState::default();
        self.calib = CalibState::default();
        self.calibrated = false;
        self.hall_offset = 0.0;
        self.current_offset = 0.0;
        self.pi_t = PiState::default();
        self.pi_i = PiState::default();
        self.sup = SupState::default();
        // `log` is left as it is: the slow pass reads only entries recorded since the loop
        // (re)started (`SupState::log_start`), and clearing 512 B would double this call.
        self.demag = DemagState::default();
        self.last_v = 0.0;
        self.ff = Linear::default();
        self.r_last = 0.0;
        self.pi_phase = false;
        self.ff_i = 0.0;
        self.i_ref = 0.0;
        self.temp_scale = 0.0;
        self.last_i = 0.0;
        self.t_floor = 0.0;
    }
}

/// Immutable part: the torque model with its rate estimator.
///
/// # Examples
///
/// ```
/// use model_core::control::{ControlConfig, ControlInput, ControlStep};
/// use model_core::models::algebraic::{Algebraic, SEED000_AVERAGE};
/// use model_core::rate::RateParams;
/// use model_core::Model;
///
/// let dt = 1e-4; // 10 kHz ADC interrupt
/// let cfg = ControlConfig { kp_t: 0.2, ..ControlConfig::defaults(dt) }.validate()?;
/// let model = Algebraic::from_params(&SEED000_AVERAGE, dt)?;
/// let step = ControlStep::new(model, RateParams::filtered(dt, 200.0)?)?;
/// let mut state = step.state();
/// // The slow supervisor pass (about 1 kHz, lower priority); NaN: no temperature sensor.
/// step.slow(&cfg, &mut state, f32::NAN);
/// // One ADC interrupt: Hall and coil-current counts at mid-scale, 24 V, 1 N·m reference.
/// let out = step.step(&cfg, &mut state, ControlInput::new(2048, 2047, 24.0, 1.0));
/// assert!(out.duty.is_finite() && out.b.is_finite() && out.torque_est.is_finite());
/// assert!(!out.pwm_enable, "the bridge stays off while the ADC offsets are calibrated");
/// # Ok::<(), model_core::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug)]
pub struct ControlStep<M: Model> {
    pub est: Estimator<M>,
}

/// `x` if finite, else `alt` (one subtraction and a compare).
#[inline(always)]
#[allow(clippy::eq_op)]
fn finite_or(x: f32, alt: f32) -> f32 {
    if x - x == 0.0 {
        x
    } else {
        alt
    }
}

/// The safe-state output of a latched fault.
#[cold]
#[inline(never)]
fn trip<S>(s: &mut ControlState<S>, b: f32, i: f32, code: FaultCode) -> ControlOutput {
    s.mode = Mode::Fault(code);
    s.last_v = 0.0;
    ControlOutput { b, current: i, torque_est: s.est.last, mode: s.mode, fault: code, ..Default::default() }
}

/// The slow pass's verdict: its fault, a stalled slow pass, or `None`.
#[inline(always)]
fn slow_verdict(k: &Coeffs, sup: &SupState) -> FaultCode {
    if sup.since_slow <= k.slow_timeout {
        FaultCode::None
    } else if sup.slow_fault != FaultCode::None {
        sup.slow_fault
    } else {
        FaultCode::SupervisorStalled
    }
}

/// A running sample tripped: the code in priority order (the slow pass's verdict, its
/// fault, which includes the slow-developing checks, or a stall; the fast conditions) and
/// the safe-state output. One cold leaf function (no nested calls), so the trip path adds
/// no stack frame.
#[cold]
#[inline(never)]
fn tripped<S>(k: &Coeffs, s: &mut ControlState<S>, x: &ControlInput, b: f32, i: f32) -> ControlOutput {
    let slow = slow_verdict(k, &s.sup);
    let code = if slow != FaultCode::None {
        slow
    } else {
        // The model-held condition is the last in the order: no need to pass it.
        let f = Fast { hall: x.hall, i, supply_v: x.supply_v, overrun: x.overrun, model_bad: true };
        supervisor::fast_code_inline(k, &f)
    };
    s.mode = Mode::Fault(code);
    s.last_v = 0.0;
    ControlOutput { b, current: i, torque_est: s.est.last, mode: s.mode, fault: code, ..Default::default() }
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

    /// The slow supervisor pass, about every millisecond (at most every
    /// [`SLOW_TIMEOUT_S`](super::config::SLOW_TIMEOUT_S)), from a task of lower priority
    /// than the sample interrupt: checks the RAM copy of the configuration
    /// ([`ValidatedConfig::verify`]) and that its time step is the model's, latching
    /// [`FaultCode::ConfigCrc`] or [`FaultCode::ConfigMismatch`] for the next sample to
    /// trip; while the loop runs, replays the samples logged since the previous pass
    /// through the slow-developing checks ([`SampleLog::judge`]: Hall noise, stuck Hall,
    /// coil open, B/i band) and latches what they find likewise; sets the temperature compensation from `temperature` (°C, NaN: no sensor)
    /// and the torque floor (the model's static torque at B = 0 from its present state).
    pub fn slow(&self, cfg: &ValidatedConfig, s: &mut ControlState<M::State>, temperature: f32) {
        let c = cfg.get();
        let dt_ok = crate::math::abs(c.dt - self.est.model.dt()) <= 1e-6 * c.dt;
        let n = s.sup.since_slow;
        let code = if !cfg.verify() {
            FaultCode::ConfigCrc
        } else if !dt_ok {
            FaultCode::ConfigMismatch
        } else if s.mode == Mode::Running && n < SLOW_LATCHED {
            let (start, offsets) = (s.sup.log_start, (s.hall_offset, s.current_offset));
            s.log.judge(cfg.coeffs(), &mut s.sup, start, n, offsets)
        } else {
            FaultCode::None
        };
        if s.sup.slow_fault == FaultCode::None {
            s.sup.slow_fault = code;
        }
        // First order, fluid datasheet slope.
        let scale = if c.temp_coeff != 0.0 && temperature.is_finite() {
            clamp(1.0 + c.temp_coeff * (temperature - c.temp_ref), 0.5, 1.5)
        } else {
            1.0
        };
        s.temp_scale = scale;
        let (model, ms, i) = (&self.est.model, &s.est.model, s.last_i);
        let t_static = |bb: f32| static_output(model, ms, bb, i) * scale;
        s.t_floor = finite_or(t_static(0.0), 0.0);
        s.ff.update(t_static, s.r_last, cfg.coeffs());
        s.sup.since_slow = if s.sup.slow_fault == FaultCode::None { 0 } else { SLOW_LATCHED };
        s.sup.log_start = 0;
        s.sup.slow_seen = true;
    }

    /// Process one sample. See the module documentation.
    ///
    /// The loop-closed path and every other mode are inlined here, one frame for both (a
    /// call from a dispatcher would cost another frame and the argument shuffle; the
    /// frame is the larger path's, 112 B).
    #[inline]
    pub fn step(&self, cfg: &ValidatedConfig, s: &mut ControlState<M::State>, x: ControlInput) -> ControlOutput {
        if s.mode == Mode::Running && x.enable {
            self.run(cfg, s, &x)
        } else {
            Self::other(cfg, s, &x)
        }
    }

    /// Every mode but an enabled `Running`.
    #[inline(always)]
    fn other(cfg: &ValidatedConfig, s: &mut ControlState<M::State>, x: &ControlInput) -> ControlOutput {
        let (c, k) = (cfg.get(), cfg.coeffs());
        s.sup.since_slow = s.sup.since_slow.wrapping_add(1);
        if !s.calibrated {
            s.hall_offset = c.hall_offset;
            s.current_offset = c.current_offset;
        }
        let b = counts_to_units(x.hall, s.hall_offset, k.hall_gain);
        let i = counts_to_units(x.current, s.current_offset, k.current_gain);
        let out = ControlOutput { b, current: i, torque_est: s.est.last, ..Default::default() };
        let early = slow_verdict(k, &s.sup);
        if early != FaultCode::None && !matches!(s.mode, Mode::Fault(_)) {
            return trip(s, b, i, early);
        }
        if matches!(s.mode, Mode::Init | Mode::Disabled) {
            // The sensor and supply checks watch the board whether or not the bridge is
            // on: a Hall wire that opens, a coil current where none can flow, a supply out
            // of its window are latched while the clutch idles, not when it is next driven.
            // (An overrun or a held estimate means nothing while nothing is driven.)
            let f = Fast { hall: x.hall, i, supply_v: x.supply_v, overrun: false, model_bad: false };
            if confirm(k, &mut s.sup, fast_any(k, &f)) {
                return trip(s, b, i, supervisor::fast_code_inline(k, &f));
            }
        }
        let mode = match s.mode {
            Mode::Fault(code) => {
                if x.reset {
                    s.reset();
                    return ControlOutput { mode: s.mode, ..out };
                }
                return ControlOutput { mode: s.mode, fault: code, ..out };
            }
            Mode::Init | Mode::Disabled if !x.enable => {
                s.last_v = 0.0;
                Mode::Disabled
            }
            Mode::Init | Mode::Disabled if !s.sup.slow_seen => s.mode,
            Mode::Init | Mode::Disabled => {
                s.calib = CalibState::default();
                if s.calibrated {
                    supervisor::prime(&mut s.sup, x.hall);
                    Mode::Running
                } else {
                    Mode::Calibrating
                }
            }
            Mode::Calibrating | Mode::Running if !x.enable => {
                s.pi_i = PiState::default();
                s.pi_t = PiState::default();
                s.i_ref = 0.0;
                s.last_v = 0.0;
                Mode::Disabled
            }
            Mode::Calibrating => {
                let f = Fast { hall: x.hall, i, supply_v: x.supply_v, overrun: x.overrun, model_bad: false };
                if confirm(k, &mut s.sup, fast_any(k, &f)) {
                    // The slow verdict is `None` here (tested above): the fast code.
                    return tripped(k, s, x, b, i);
                }
                let cal = Calibration {
                    samples: c.calib_samples as u16,
                    max_spread: c.calib_max_spread as u16,
                    nominal_hall: c.hall_offset,
                    nominal_current: c.current_offset,
                    max_offset_error: c.calib_max_offset_error,
                };
                match cal.step(&mut s.calib, x.hall, x.current) {
                    CalibResult::Pending => Mode::Calibrating,
                    CalibResult::Failed => return trip(s, b, i, FaultCode::CalibrationFailed),
                    CalibResult::Done { hall_offset, current_offset } => {
                        s.hall_offset = hall_offset;
                        s.current_offset = current_offset;
                        s.calibrated = true;
                        supervisor::prime(&mut s.sup, x.hall);
                        Mode::Running
                    }
                }
            }
            // Not reached (`step` runs an enabled `Running` itself); bridge off if it were.
            Mode::Running => Mode::Running,
        };
        s.mode = mode;
        ControlOutput { mode, ..out }
    }

    /// The loop closed: estimate, supervise, feed-forward, two PIs, duty.
    #[inline(always)]
    fn run(&self, cfg: &ValidatedConfig, s: &mut ControlState<M::State>, x: &ControlInput) -> ControlOutput {
        let k = cfg.coeffs();
        let n = s.sup.since_slow.wrapping_add(1);
        s.sup.since_slow = n;
        // The slow-developing checks run in the slow pass, on this record of the sample.
        s.log.record(n, x.hall, x.current, s.last_v);
        // Finite by construction: u16 counts, validated gains and offsets.
        let b = counts_to_units(x.hall, s.hall_offset, k.hall_gain);
        let i = counts_to_units(x.current, s.current_offset, k.current_gain);
        s.last_i = i;
        let est = self.est.step_finite(&mut s.est, b, i);
        let model_bad = !est.flags.ok();

        // A supply outside its window (NaN: v_min) trips within `confirm` samples; until
        // then the duty is computed for the nearest value inside it.
        let (supply, supply_bad) = supervisor::supply_window(k, x.supply_v);
        let f = Fast { hall: x.hall, i, supply_v: x.supply_v, overrun: x.overrun, model_bad };
        let fast = confirm(k, &mut s.sup, fast_any_with(k, &f, supply_bad));
        let slow = n > k.slow_timeout;
        if fast | slow {
            return tripped(k, s, x, b, i);
        }

        let mut fl = if model_bad { flags::ESTIMATE_HELD } else { 0 };
        let scale = s.temp_scale;
        let t_est = finite_or(est.y * scale, 0.0);
        // Reference limited to ±ref_lim, NaN → 0 (`math::clamp_symmetric`, with the flag set
        // in its out-of-range branch).
        let (r0, lim) = (x.reference, k.ref_lim);
        let r = if crate::math::abs(r0) <= lim {
            r0
        } else {
            fl |= flags::REFERENCE_LIMITED;
            crate::math::limit_sign(r0, lim)
        };
        let i_ref = match k.mode {
            LoopMode::Torque => {
                // The torque loop runs at half the sample rate in two phases on alternate
                // samples, the current loop below every sample: the feed-forward, then
                // the PI on it and on this sample's estimate; its output is held between.
                s.pi_phase = !s.pi_phase;
                if s.pi_phase {
                    let e = s.r_last - t_est;
                    s.i_ref = step_limited(k.kp_t, k.ki_t_dt, &mut s.pi_t, e, s.ff_i, 0.0, k.i_max);
                } else {
                    // Below the torque at B = 0 (from the slow pass) nothing can be
                    // reached: aim there.
                    let t0 = s.t_floor;
                    let r_eff = if t0 > r { t0 } else { r };
                    // The lead acts on the reference, ahead of the feed-forward's affine
                    // map (the same as on its current while the map holds).
                    let r_lead = r_eff + k.lead * (r_eff - s.r_last);
                    s.r_last = r_eff;
                    s.ff_i = s.ff.current(r_lead);
                }
                s.i_ref
            }
            LoopMode::OpenLoopTorque => StaticMap { a: cfg.get().map }.current(r, k.i_max),
            LoopMode::Current => r,
        };
        let v_lim = k.duty_max * supply;
        let demag = Demag { duty: k.demag_duty, samples: k.demag_samples, threshold: k.demag_threshold };
        let (v, d) = match demag.step(&mut s.demag, r, i) {
            Some(d) => {
                fl |= flags::DEMAG;
                s.pi_i = PiState::default();
                s.pi_t = PiState::default();
                (d * supply, d)
            }
            None => {
                let v = step_limited(k.kp_i, k.ki_i_dt, &mut s.pi_i, i_ref - i, k.coil_r * i_ref, -v_lim, v_lim);
                if crate::math::abs(v) >= v_lim {
                    fl |= flags::SATURATED;
                }
                (v, v / supply)
            }
        };
        // |v| ≤ v_lim = duty_max·supply and the pulse's duty ≤ duty_max (validated): |d| ≤
        // duty_max up to rounding, so no clamp here.
        let (duty, compare) = quantise(d, k.pwm_counts);
        s.last_v = v;
        ControlOutput {
            duty,
            compare,
            pwm_enable: true,
            b,
            current: i,
            torque_est: t_est,
            i_ref,
            v_cmd: v,
            mode: Mode::Running,
            fault: FaultCode::None,
            flags: fl,
        }
    }
}

#[cfg(test)]
mod tests;
