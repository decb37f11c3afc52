//! The firmware's control step ([`model_core::control`]) against the simulated clutch.
//!
//! Per sample of `1/control_hz` s: the plant's ADCs are sampled (12-bit Hall and current
//! counts, supply voltage, temperature), the control step computes the new duty (PWM
//! quantised to the timer's compare counts), and that duty is applied from the **next**
//! sample on (one-sample computation delay); between samples the plant integrates every
//! PWM edge ([`crate::plant`]). The true torque is the plant's.
//! The slow supervisor pass (`ControlStep::slow`) runs every millisecond, as in the firmware.
//!
//! [`identify`] plays the lab: on the simulated clutch, with the same step in current
//! mode as the current driver, it records sines and a slow triangle, fits seed 000's
//! algebraic model (eq. 14, linear least squares on Hall B, its rate from the
//! controller's own rate estimator, and the load-cell torque) for the closed loop, and the
//! static current → torque map for the **baseline** (open-loop current control, what a
//! user without B sensing has).

use model_core::control::{ControlConfig, ControlInput, ControlStep, FaultCode, LoopMode, Mode, ValidatedConfig};
use model_core::models::algebraic::Algebraic;
use model_core::rate::{RateParams, RateState};
use model_core::{Finite, Kin, Model, ParamError};
use serde::Serialize;
use thiserror::Error;

use crate::metrics::{metrics, Metrics};
use crate::plant::coil::CoilFault;
use crate::plant::sensors::HallFault;
use crate::plant::{ClutchParams, Plant};

/// Why a loop run could not be set up.
#[derive(Debug, Error)]
pub enum LoopError {
    #[error("controller parameters: {0}")]
    Params(#[from] ParamError),
    #[error("identification failed: {0}")]
    Identify(String),
}

/// Cut-off of the controller's rate estimator (filtered difference), Hz.
pub const RATE_FC_HZ: f32 = 150.0;
/// Time the loop gets before the reference starts (calibration 0.1 s + margin), s.
pub const T_START: f64 = 0.15;

/// One run, sample by sample (plain vectors for CSV and plots).
#[derive(Clone, Debug, Default, Serialize)]
pub struct Run {
    pub t: Vec<f64>,
    pub reference: Vec<f64>,
    pub torque_est: Vec<f64>,
    pub torque_true: Vec<f64>,
    pub load_cell: Vec<f64>,
    pub b: Vec<f64>,
    pub current: Vec<f64>,
    pub coil_current: Vec<f64>,
    pub i_ref: Vec<f64>,
    pub duty: Vec<f64>,
    pub speed: Vec<f64>,
    pub temperature: Vec<f64>,
    pub fault: Vec<u8>,
    pub pwm_enable: Vec<bool>,
}

impl Run {
    /// Samples with `t ≥ from`.
    pub fn after(&self, from: f64) -> usize {
        self.t.iter().position(|t| *t >= from).unwrap_or(self.t.len())
    }
    /// Tracking metrics of the true torque against the reference from `from` s on.
    pub fn tracking(&self, from: f64) -> Metrics {
        let k = self.after(from);
        metrics(&self.reference[k..], &self.torque_true[k..], None)
    }
    /// CSV text: `t,reference,torque_est,torque,i,i_ref,duty,b,speed,temperature,fault`.
    pub fn csv(&self) -> String {
        let mut s = String::from("t,reference,torque_est,torque,i,i_ref,duty,b,speed,temperature,fault\n");
        for k in 0..self.t.len() {
            s += &format!(
                "{:.5},{:.5},{:.5},{:.5},{:.5},{:.5},{:.5},{:.6},{:.3},{:.3},{}\n",
                self.t[k],
                self.reference[k],
                self.torque_est[k],
                self.torque_true[k],
                self.current[k],
                self.i_ref[k],
                self.duty[k],
                self.b[k],
                self.speed[k],
                self.temperature[k],
                self.fault[k]
            );
        }
        s
    }
}

/// A fault injected by `hil-sim loop --scenario faults`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Injection {
    HallOpen,
    HallShort,
    HallStuck,
    HallNoise,
    CoilOpen,
    CoilShort,
    SupplyDroop,
    ConfigCrc,
    ModelNan,
    Overrun,
}

impl Injection {
    pub const ALL: [Self; 10] = [
        Self::HallOpen,
        Self::HallShort,
        Self::HallStuck,
        Self::HallNoise,
        Self::CoilOpen,
        Self::CoilShort,
        Self::SupplyDroop,
        Self::ConfigCrc,
        Self::ModelNan,
        Self::Overrun,
    ];
    pub const fn name(self) -> &'static str {
        match self {
            Self::HallOpen => "hall_open",
            Self::HallShort => "hall_short",
            Self::HallStuck => "hall_stuck",
            Self::HallNoise => "hall_noise",
            Self::CoilOpen => "coil_open",
            Self::CoilShort => "coil_short",
            Self::SupplyDroop => "supply_droop",
            Self::ConfigCrc => "config_crc",
            Self::ModelNan => "model_nan",
            Self::Overrun => "overrun",
        }
    }
    /// The fault code the supervisor should latch.
    pub const fn expected(self) -> FaultCode {
        match self {
            Self::HallOpen => FaultCode::HallOpen,
            Self::HallShort => FaultCode::HallShort,
            Self::HallStuck => FaultCode::HallStuck,
            Self::HallNoise => FaultCode::HallNoise,
            Self::CoilOpen => FaultCode::CoilOpen,
            Self::CoilShort => FaultCode::OverCurrent,
            Self::SupplyDroop => FaultCode::SupplyLow,
            Self::ConfigCrc => FaultCode::ConfigCrc,
            Self::ModelNan => FaultCode::ModelNonFinite,
            Self::Overrun => FaultCode::Overrun,
        }
    }
}

/// A model that emits NaN from its `after`-th step on (fault injection for "NaN from a
/// model"); otherwise exactly the inner model.
#[derive(Clone, Copy, Debug)]
pub struct NanAfter<M: Model> {
    pub inner: M,
    pub after: u32,
}

/// State of [`NanAfter`]: the inner state and a step counter.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NanState<S> {
    pub inner: S,
    pub steps: u32,
}

impl<S: Finite> Finite for NanState<S> {
    fn is_finite(&self) -> bool {
        self.inner.is_finite()
    }
}

impl<M: Model> Model for NanAfter<M> {
    type State = NanState<M::State>;
    const ID: &'static str = "nan_after";
    const PARAM_NAMES: &'static [&'static str] = M::PARAM_NAMES;
    const N_PARAMS: usize = M::N_PARAMS;
    fn from_params(values: &[f32], dt: f32) -> Result<Self, ParamError> {
        Ok(Self { inner: M::from_params(values, dt)?, after: u32::MAX })
    }
    fn write_params(&self, out: &mut [f32]) -> usize {
        self.inner.write_params(out)
    }
    fn dt(&self) -> f32 {
        self.inner.dt()
    }
    fn step(&self, s: &mut Self::State, k: &Kin) -> f32 {
        s.steps = s.steps.saturating_add(1);
        if s.steps > self.after {
            return f32::NAN;
        }
        self.inner.step(&mut s.inner, k)
    }
}

/// Faults scheduled in a run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Schedule {
    pub injection: Injection,
    /// Injection time, s.
    pub at: f64,
}

/// Run `step` with configuration `cfg` against a fresh plant for `duration` s.
/// `reference(t)` is in N·m (A in current mode); it is applied from [`T_START`] on
/// (0 before, while the controller calibrates).
pub fn run<M: Model>(
    clutch: &ClutchParams,
    step: &ControlStep<M>,
    mut cfg: ValidatedConfig,
    reference: &dyn Fn(f64) -> f64,
    duration: f64,
    seed: u64,
    fault: Option<Schedule>,
) -> Run {
    let dt = f64::from(cfg.get().dt);
    let n = (duration / dt).round() as usize;
    let mut plant = Plant::new(clutch.clone(), seed);
    let mut st = step.state();
    let mut applied = (0.0f64, false);
    let mut out = Run::default();
    let mut injected = false;
    let use_temp = cfg.get().temp_coeff != 0.0;
    // The slow supervisor pass at 1 kHz, as the firmware's `supervisor` task runs it.
    let slow_every = ((1e-3 / dt).round() as usize).max(1);
    for k in 0..n {
        let t = k as f64 * dt;
        let active = fault.filter(|f| t >= f.at).map(|f| f.injection);
        if let (Some(inj), false) = (active, injected) {
            injected = true;
            match inj {
                Injection::HallOpen => plant.faults.hall = HallFault::Open,
                Injection::HallShort => plant.faults.hall = HallFault::Short,
                Injection::HallStuck => plant.faults.hall = HallFault::Stuck(plant.hall_now()),
                Injection::HallNoise => plant.faults.hall = HallFault::Noise(300.0),
                Injection::CoilOpen => plant.faults.coil = CoilFault::Open,
                Injection::CoilShort => plant.faults.coil = CoilFault::Short,
                Injection::SupplyDroop => plant.faults.supply_v = Some(0.5 * clutch.coil.supply_v),
                Injection::ConfigCrc => cfg.inject_bit_flip(0x2A5),
                Injection::ModelNan | Injection::Overrun => {}
            }
        }
        let overrun = active == Some(Injection::Overrun);
        let m = plant.measure();
        let r = if t >= T_START { reference(t - T_START) } else { 0.0 };
        if k % slow_every == 0 {
            step.slow(&cfg, &mut st, if use_temp { m.temperature as f32 } else { f32::NAN });
        }
        let input = ControlInput { overrun, ..ControlInput::new(m.hall, m.current, m.supply_v as f32, r as f32) };
        let o = step.step(&cfg, &mut st, input);
        out.t.push(t);
        out.reference.push(r);
        out.torque_est.push(f64::from(o.torque_est));
        out.torque_true.push(plant.torque);
        out.load_cell.push(plant.load_cell);
        out.b.push(f64::from(o.b));
        out.current.push(f64::from(o.current));
        out.coil_current.push(plant.coil.i);
        out.i_ref.push(f64::from(o.i_ref));
        out.duty.push(applied.0);
        out.speed.push(plant.omega);
        out.temperature.push(plant.theta);
        out.fault.push(o.fault.code());
        out.pwm_enable.push(applied.1);
        plant.advance(applied.0, applied.1, dt);
        // An overrunning step delivers its duty late: the old one stays for this period,
        // except that a tripped supervisor's safe state is applied at once.
        if !overrun || o.fault != FaultCode::None {
            applied = (f64::from(o.duty), o.pwm_enable);
        }
    }
    out
}

/// Controller settings and models identified on one clutch.
#[derive(Clone, Debug, Serialize)]
pub struct Identified {
    /// Algebraic model (seed 000 eq. 14) `[k, c, alpha, t0]`, B in T.
    pub algebraic: [f32; 4],
    /// R-RMSE of the fitted algebraic model on its training data.
    pub algebraic_fit_r_rmse: f64,
    /// Baseline static map `[a0, a1, a2, a3]`.
    pub map: [f32; 4],
    pub map_fit_r_rmse: f64,
    /// Static B/i slope, T/A.
    pub b_per_amp: f32,
    /// Sample period, s.
    pub dt: f32,
    #[serde(skip)]
    pub torque_cfg: ControlConfig,
}

/// Solve the normal equations of a linear least-squares fit `y ≈ X·θ` (Gauss–Jordan).
pub fn least_squares<const N: usize>(rows: &[[f64; N]], y: &[f64]) -> Option<[f64; N]> {
    let mut a = [[0.0; N]; N];
    let mut b = [0.0; N];
    for (x, yv) in rows.iter().zip(y) {
        for i in 0..N {
            b[i] += x[i] * yv;
            for j in 0..N {
                a[i][j] += x[i] * x[j];
            }
        }
    }
    for c in 0..N {
        let p = (c..N).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))?;
        if a[p][c].abs() < 1e-300 {
            return None;
        }
        a.swap(c, p);
        b.swap(c, p);
        for r in 0..N {
            if r != c {
                let f = a[r][c] / a[c][c];
                let row = a[c];
                for (v, w) in a[r].iter_mut().zip(row) {
                    *v -= f * w;
                }
                b[r] -= f * b[c];
            }
        }
    }
    let mut x = [0.0; N];
    for i in 0..N {
        x[i] = b[i] / a[i][i];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// A current-mode controller (the current driver) at `control_hz`.
pub fn current_driver(
    clutch: &ClutchParams,
    control_hz: f64,
) -> Result<(ControlStep<Algebraic>, ValidatedConfig), LoopError> {
    let dt = (1.0 / control_hz) as f32;
    let placeholder = Algebraic::new(0.0, 0.0, 0.0, 0.0, dt)?;
    let step = ControlStep::new(placeholder, RateParams::filtered(dt, RATE_FC_HZ)?)?;
    let cfg = ControlConfig { mode: LoopMode::Current, ..base_config(clutch, dt, 0.2) };
    Ok((step, cfg.validate()?))
}

/// Settings a firmware engineer derives from the clutch's data sheet values (nominal
/// sensor gains, coil R and L) and the identified B/i slope.
pub fn base_config(clutch: &ClutchParams, dt: f32, b_per_amp: f32) -> ControlConfig {
    let s = &clutch.sensors;
    let c = &clutch.coil;
    // Current loop: PI zero on the coil pole, crossover 300 Hz (≪ 10 kHz loop rate).
    let wc = 2.0 * std::f64::consts::PI * 300.0;
    ControlConfig {
        hall_gain: (1.0 / s.hall_counts_per_t()) as f32,
        current_gain: (1.0 / s.current_counts_per_a()) as f32,
        calib_samples: (0.1 / f64::from(dt)).round() as f32,
        coil_r: c.r20 as f32,
        b_per_amp,
        kp_i: (c.l * wc) as f32,
        ki_i: (c.r20 * wc) as f32,
        v_min: (0.75 * c.supply_v) as f32,
        v_max: (1.25 * c.supply_v) as f32,
        // 16 identical counts in a row never happen with ≥ 1 count of sensor noise.
        stuck_samples: if s.noise { 16.0 } else { 0.0 },
        ..ControlConfig::defaults(dt)
    }
}

/// Identify the algebraic model and the baseline map on `clutch` (see module docs).
pub fn identify(clutch: &ClutchParams, control_hz: f64, seed: u64) -> Result<Identified, LoopError> {
    let (drv, cfg) = current_driver(clutch, control_hz)?;
    let dt = cfg.get().dt;
    let err = |m: &str| LoopError::Identify(m.to_owned());
    // Static map: slow triangle 0–3 A, both branches.
    let tri = |t: f64| 1.5 + 1.5 * crate::excitation::Excitation::Triangle { f: 0.25 }.at(t - 1.0).x;
    let r = run(clutch, &drv, cfg, &tri, 9.0, seed, None);
    let k0 = r.after(T_START + 1.0);
    let rows: Vec<[f64; 4]> = r.current[k0..].iter().map(|i| [1.0, i.abs(), i * i, i.abs().powi(3)]).collect();
    let map = least_squares(&rows, &r.load_cell[k0..]).ok_or_else(|| err("static map is singular"))?;
    let map_fit: Vec<f64> = rows.iter().map(|x| x.iter().zip(&map).map(|(a, b)| a * b).sum()).collect();
    let map_fit_r_rmse = metrics(&r.load_cell[k0..], &map_fit, None).r_rmse;
    let bi: Vec<[f64; 1]> = r.current[k0..].iter().map(|i| [*i]).collect();
    let [b_per_amp] = least_squares(&bi, &r.b[k0..]).ok_or_else(|| err("B/i slope"))?;
    // Algebraic model: seed 000's fitting sines 1–9 Hz, 0–3 A, 2 s each.
    let rate = RateParams::filtered(dt, RATE_FC_HZ)?;
    let (mut rows, mut y) = (Vec::new(), Vec::new());
    for f in [1.0, 3.0, 5.0, 7.0, 9.0] {
        let sine = move |t: f64| 1.5 - 1.5 * (2.0 * std::f64::consts::PI * f * t).cos();
        let r = run(clutch, &drv, cfg, &sine, T_START + 2.5, seed ^ (f as u64), None);
        let mut rs = RateState::default();
        let k0 = r.after(T_START + 0.5);
        for (k, b) in r.b.iter().enumerate() {
            let (db, _) = rate.step(&mut rs, *b as f32);
            if k >= k0 {
                rows.push([*b, f64::from(db), b.abs() * b.powi(3), 1.0]);
                y.push(r.load_cell[k]);
            }
        }
    }
    let th = least_squares(&rows, &y).ok_or_else(|| err("algebraic fit is singular"))?;
    let fit: Vec<f64> = rows.iter().map(|x| x.iter().zip(&th).map(|(a, b)| a * b).sum()).collect();
    let algebraic_fit_r_rmse = metrics(&y, &fit, None).r_rmse;
    let algebraic = th.map(|v| v as f32);
    let b_per_amp = b_per_amp as f32;
    let [k, c, _, _] = algebraic;
    // Torque loop: the plant from current reference to torque estimate is ≈ K = k·B/i
    // (N·m/A) behind the current loop and the Hall lag; an integral-dominant PI with a
    // 20 Hz crossover (the estimate carries the model's lag −c/k ≈ 3 ms, so a faster
    // integral action peaks), and the feed-forward lead equal to that lag.
    let gain = (k * b_per_amp).max(1e-3);
    let wt = 2.0 * std::f32::consts::PI * 20.0;
    let torque_cfg = ControlConfig {
        mode: LoopMode::Torque,
        kp_t: 0.1 / gain,
        ki_t: wt / gain,
        ff_lead_s: (-c / k).clamp(0.0, 0.02),
        b_max: (clutch.magnetic.b_sat * 0.95) as f32,
        map: map.map(|v| v as f32),
        ..base_config(clutch, dt, b_per_amp)
    };
    Ok(Identified { algebraic, algebraic_fit_r_rmse, map: torque_cfg.map, map_fit_r_rmse, b_per_amp, dt, torque_cfg })
}

impl Identified {
    /// The closed-loop controller (algebraic model, optionally NaN-injecting after `nan_after` model steps).
    pub fn loop_step(&self, nan_after: u32) -> Result<ControlStep<NanAfter<Algebraic>>, LoopError> {
        let [k, c, a, t0] = self.algebraic;
        let m = NanAfter { inner: Algebraic::new(k, c, a, t0, self.dt)?, after: nan_after };
        Ok(ControlStep::new(m, RateParams::filtered(self.dt, RATE_FC_HZ)?)?)
    }
    /// Settings of the closed loop (with temperature compensation `temp_coeff`, 1/K).
    pub fn loop_config(&self, temp_coeff: f32) -> Result<ValidatedConfig, LoopError> {
        Ok(ControlConfig { temp_coeff, ..self.torque_cfg }.validate()?)
    }
    /// Settings of the baseline: open-loop current control through the static map.
    pub fn baseline_config(&self) -> Result<ValidatedConfig, LoopError> {
        Ok(ControlConfig { mode: LoopMode::OpenLoopTorque, ..self.torque_cfg }.validate()?)
    }
}

/// Result of one injected fault.
#[derive(Clone, Debug, Serialize)]
pub struct FaultResult {
    pub fault: &'static str,
    pub detected: bool,
    /// From the first faulty sample to the end of the step that commands the safe state, ms.
    pub detect_ms: Option<f64>,
    /// PWM off and coil current below 50 mA at the end of the run.
    pub safe_state: bool,
    pub code: u8,
    pub code_name: &'static str,
    pub expected_code: u8,
    /// Time from detection until the coil current fell below 50 mA, ms.
    pub de_energised_ms: Option<f64>,
    /// A fault latched before the injection (a false trip).
    pub tripped_before_injection: bool,
}

/// Inject `inj` alone at 0.3 s into a multisine torque run and report.
pub fn fault_run(
    id: &Identified,
    clutch: &ClutchParams,
    inj: Injection,
    seed: u64,
) -> Result<(FaultResult, Run), LoopError> {
    let dt = f64::from(id.dt);
    let at = T_START + 0.3;
    let cfg = id.loop_config(0.0)?;
    // The model is first called on the first running sample, after the init sample and the calibration.
    let first_model_sample = 1 + cfg.get().calib_samples as u32;
    // First sample index whose time is ≥ `at`, computed as `run` does.
    let k_at = (0u32..).find(|&k| f64::from(k) * dt >= at).unwrap_or(0);
    let nan_after = if inj == Injection::ModelNan { k_at.saturating_sub(first_model_sample) } else { u32::MAX };
    let step = id.loop_step(nan_after)?;
    let ms = crate::excitation::Excitation::seed000_multisine();
    let reference = move |t: f64| 6.0 + 4.0 * ms.at(t).x;
    let r = run(clutch, &step, cfg, &reference, at + 0.1, seed, Some(Schedule { injection: inj, at }));
    let k_inj = r.after(at);
    let tripped_before_injection = r.fault[..k_inj].iter().any(|c| *c != 0);
    let k_det = r.fault[k_inj..].iter().position(|c| *c != 0).map(|p| p + k_inj);
    let code = k_det.map_or(0, |k| r.fault[k]);
    let de_energised_ms =
        k_det.and_then(|kd| r.coil_current[kd..].iter().position(|i| i.abs() < 0.05).map(|p| p as f64 * dt * 1e3));
    let end_ok = r.pwm_enable.last() == Some(&false) && r.coil_current.last().is_some_and(|i| i.abs() < 0.05);
    let name =
        |c: u8| Injection::ALL.iter().map(|i| i.expected()).find(|f| f.code() == c).map_or("none", FaultCode::name);
    let res = FaultResult {
        fault: inj.name(),
        detected: k_det.is_some(),
        detect_ms: k_det.map(|k| (k - k_inj + 1) as f64 * dt * 1e3),
        safe_state: end_ok,
        code,
        code_name: if code == 0 { "none" } else { name(code) },
        expected_code: inj.expected().code(),
        de_energised_ms,
        tripped_before_injection,
    };
    Ok((res, r))
}

/// The multisine torque reference of the `multisine` scenario: seed 000 eq. 21 mapped to
/// 6 ± 4 N·m (2–10 N·m).
pub fn multisine_reference() -> impl Fn(f64) -> f64 {
    let ms = crate::excitation::Excitation::seed000_multisine();
    move |t: f64| 6.0 + 4.0 * ms.at(t).x
}

/// Closed loop and baseline on the same reference: `(loop run, baseline run)`.
pub fn compare(
    id: &Identified,
    clutch: &ClutchParams,
    reference: &dyn Fn(f64) -> f64,
    duration: f64,
    temp_coeff: f32,
    seed: u64,
) -> Result<(Run, Run), LoopError> {
    let step = id.loop_step(u32::MAX)?;
    let lp = run(clutch, &step, id.loop_config(temp_coeff)?, reference, duration, seed, None);
    let bl = run(clutch, &step, id.baseline_config()?, reference, duration, seed, None);
    Ok((lp, bl))
}

/// Whether a mode is the latched fault state.
pub fn is_fault(m: Mode) -> bool {
    matches!(m, Mode::Fault(_))
}

/// Gain |T/r| of the true torque at frequency `f` over samples `[k0, k1)`.
fn gain_at(r: &Run, f: f64, k0: usize, k1: usize) -> f64 {
    let w = 2.0 * std::f64::consts::PI * f;
    let (mut yr, mut yi, mut xr, mut xi) = (0.0, 0.0, 0.0, 0.0);
    for k in k0..k1 {
        let (c, s) = ((w * r.t[k]).cos(), (w * r.t[k]).sin());
        yr += r.torque_true[k] * c;
        yi += r.torque_true[k] * s;
        xr += r.reference[k] * c;
        xi += r.reference[k] * s;
    }
    (yr.hypot(yi)) / xr.hypot(xi).max(1e-300)
}

/// A point of a measured frequency response.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct GainPoint {
    pub f_hz: f64,
    pub gain: f64,
}

/// Stepped-sine frequencies of the `sweep` scenario, Hz.
pub const SWEEP_HZ: [f64; 12] = [2.0, 5.0, 10.0, 20.0, 30.0, 50.0, 70.0, 100.0, 150.0, 200.0, 300.0, 500.0];

/// Frequency response of the true torque to a ±`amp` N·m sine around `mean` N·m, one
/// stepped sine per frequency in [`SWEEP_HZ`] (settle ≥ 0.1 s, measure ≥ 0.2 s, whole periods).
pub fn frequency_response<M: Model>(
    clutch: &ClutchParams,
    step: &ControlStep<M>,
    cfg: ValidatedConfig,
    mean: f64,
    amp: f64,
    seed: u64,
) -> Vec<GainPoint> {
    let mut segs = Vec::new();
    let mut t0 = 0.0;
    for f in SWEEP_HZ {
        let settle = (0.1 * f).ceil() / f;
        let meas = (0.2 * f).ceil().max(4.0) / f;
        segs.push((f, t0, t0 + settle, t0 + settle + meas));
        t0 += settle + meas;
    }
    let segs2 = segs.clone();
    let reference = move |t: f64| {
        let seg = segs2.iter().find(|s| t < s.3).or(segs2.last());
        seg.map_or(mean, |&(f, start, _, _)| mean + amp * (2.0 * std::f64::consts::PI * f * (t - start)).sin())
    };
    let r = run(clutch, step, cfg, &reference, T_START + t0, seed, None);
    segs.iter()
        .map(|&(f, start, m0, m1)| {
            // Phase reference of gain_at is absolute time; both signals share it.
            let _ = start;
            GainPoint { f_hz: f, gain: gain_at(&r, f, r.after(T_START + m0), r.after(T_START + m1)) }
        })
        .collect()
}

/// −3 dB frequency: where the gain first falls below `1/√2` of the lowest frequency's,
/// interpolated in log frequency; `None` if it never does.
pub fn bandwidth(points: &[GainPoint]) -> Option<f64> {
    let g0 = points.first()?.gain;
    let lim = g0 / 2f64.sqrt();
    points.windows(2).find(|w| w[1].gain < lim).map(|w| {
        let (a, b) = (w[0], w[1]);
        let frac = (a.gain - lim) / (a.gain - b.gain);
        (a.f_hz.ln() + frac * (b.f_hz.ln() - a.f_hz.ln())).exp()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn least_squares_recovers_a_line() {
        let rows: Vec<[f64; 2]> = (0..10).map(|k| [1.0, k as f64]).collect();
        let y: Vec<f64> = (0..10).map(|k| 2.0 + 0.5 * k as f64).collect();
        let th = least_squares(&rows, &y).unwrap();
        assert!((th[0] - 2.0).abs() < 1e-9 && (th[1] - 0.5).abs() < 1e-9);
        assert!(least_squares(&[[0.0, 0.0]], &[1.0]).is_none());
    }
}
