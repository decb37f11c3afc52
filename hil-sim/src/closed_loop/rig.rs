//! One sample of the closed loop on the bench: a scheduled fault put in at its time, the
//! plant measured, the slow supervisor pass at 1 kHz, the controller's step, the duty
//! applied from the next sample on (one-sample computation delay; an overrunning step's
//! duty one period late). `harness::run` (what `hil-sim loop` computes) and
//! `hil-sim virtual-board` both step this, so the two give the same numbers.

use model_core::control::{ControlInput, ControlOutput, ControlState, ControlStep, FaultCode, ValidatedConfig};
use model_core::Model;

use super::injection::{Injection, Schedule};
use crate::sim::plant::{ClutchParams, Plant};

/// A controller the rig drives: the firmware's control step with its state.
pub trait Controller {
    /// The slow supervisor pass (temperature °C, NaN when unknown).
    fn slow(&mut self, cfg: &ValidatedConfig, temperature: f32);
    /// One control step.
    fn step(&mut self, cfg: &ValidatedConfig, x: ControlInput) -> ControlOutput;
}

/// A control step of model `M` with its state.
pub struct Stepped<'a, M: Model>(pub &'a ControlStep<M>, pub ControlState<M::State>);

impl<M: Model> Controller for Stepped<'_, M> {
    fn slow(&mut self, cfg: &ValidatedConfig, temperature: f32) {
        self.0.slow(cfg, &mut self.1, temperature);
    }
    fn step(&mut self, cfg: &ValidatedConfig, x: ControlInput) -> ControlOutput {
        self.0.step(cfg, &mut self.1, x)
    }
}

impl Controller for firmware::runner::Loop {
    fn slow(&mut self, cfg: &ValidatedConfig, temperature: f32) {
        firmware::runner::Loop::slow(self, cfg, temperature);
    }
    fn step(&mut self, cfg: &ValidatedConfig, x: ControlInput) -> ControlOutput {
        firmware::runner::Loop::step(self, cfg, x)
    }
}

/// What the host sets for one sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Command {
    /// N·m (A in current mode).
    pub reference: f64,
    pub enable: bool,
    pub reset: bool,
}

/// One sample's figures, taken before the plant advances.
#[derive(Clone, Copy, Debug)]
pub struct Sampled {
    /// s since the start.
    pub t: f64,
    pub out: ControlOutput,
    /// The plant's torque and load cell, N·m; coil current, A.
    pub torque_true: f64,
    pub load_cell: f64,
    pub coil_current: f64,
    /// The duty and bridge state applied during this sample.
    pub applied: (f64, bool),
    pub speed: f64,
    pub temperature: f64,
}

/// The plant and what the bench keeps between samples.
pub struct Rig {
    clutch: ClutchParams,
    pub plant: Plant,
    fault: Option<Schedule>,
    injected: bool,
    applied: (f64, bool),
    slow_every: usize,
    /// Temperature compensation configured (decided once, at the start).
    use_temp: bool,
    /// Time step, s (the running page's control period).
    dt: f64,
    k: usize,
    /// Samples and time, s, at the last change of time step (a page at another control
    /// rate): time is `t0 + (k - k0)·dt`, the slow pass every `slow_every` samples from `k0`.
    k0: usize,
    t0: f64,
}

/// Samples between slow supervisor passes at time step `dt`, s: the pass at
/// [`SLOW_HZ`](firmware::runner::SLOW_HZ), as the firmware's `supervisor` task asks for it.
fn slow_every(dt: f64) -> usize {
    ((1.0 / f64::from(firmware::runner::SLOW_HZ) / dt).round() as usize).max(1)
}

impl Rig {
    /// A fresh plant (noise seed `seed`) at the time step of `cfg`, with `fault` scheduled.
    pub fn new(clutch: &ClutchParams, cfg: &ValidatedConfig, seed: u64, fault: Option<Schedule>) -> Self {
        let dt = f64::from(cfg.get().dt);
        Self {
            clutch: clutch.clone(),
            plant: Plant::new(clutch.clone(), seed),
            fault,
            injected: false,
            applied: (0.0, false),
            slow_every: slow_every(dt),
            use_temp: cfg.get().temp_coeff != 0.0,
            dt,
            k: 0,
            k0: 0,
            t0: 0.0,
        }
    }

    /// From the next sample on, step at `dt`, s (a page swapped in at another control
    /// rate; the firmware's repetition counter changes the same way).
    pub fn set_dt(&mut self, dt: f64) {
        if dt == self.dt || !(dt.is_finite() && dt > 0.0) {
            return;
        }
        self.t0 = self.time();
        self.k0 = self.k;
        self.dt = dt;
        self.slow_every = slow_every(dt);
    }

    /// Time of the next sample, s.
    pub fn time(&self) -> f64 {
        self.t0 + (self.k - self.k0) as f64 * self.dt
    }

    /// The time step, s.
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Samples run so far.
    pub fn samples(&self) -> usize {
        self.k
    }

    /// Run one sample of `ctrl` with configuration `cfg` (a configuration fault changes it).
    pub fn sample(&mut self, ctrl: &mut dyn Controller, cfg: &mut ValidatedConfig, cmd: Command) -> Sampled {
        let t = self.time();
        let active = self.fault.filter(|f| t >= f.at).map(|f| f.injection);
        if let (Some(inj), false) = (active, self.injected) {
            self.injected = true;
            inj.apply(&self.clutch, &mut self.plant, cfg);
        }
        let overrun = active == Some(Injection::Overrun);
        let m = self.plant.measure();
        if (self.k - self.k0).is_multiple_of(self.slow_every) {
            ctrl.slow(cfg, if self.use_temp { m.temperature as f32 } else { f32::NAN });
        }
        let input = ControlInput {
            overrun,
            enable: cmd.enable,
            reset: cmd.reset,
            ..ControlInput::new(m.hall, m.current, m.supply_v as f32, cmd.reference as f32)
        };
        let o = ctrl.step(cfg, input);
        let p = &self.plant;
        let s = Sampled {
            t,
            out: o,
            torque_true: p.torque,
            load_cell: p.load_cell,
            coil_current: p.coil.i,
            applied: self.applied,
            speed: p.omega,
            temperature: p.theta,
        };
        self.plant.advance(self.applied.0, self.applied.1, self.dt);
        // An overrunning step delivers its duty late: the old one stays for this period,
        // except that a tripped supervisor's safe state is applied at once.
        if !overrun || o.fault != FaultCode::None {
            self.applied = (f64::from(o.duty), o.pwm_enable);
        }
        self.k += 1;
        s
    }
}
