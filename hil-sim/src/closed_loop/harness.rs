//! One closed-loop run, sample by sample: ADC samples → control step → duty applied from
//! the next sample on (one-sample computation delay), the plant integrating every PWM edge
//! in between; the slow supervisor pass at 1 kHz. Times in s, torques in N·m, B in T.

use model_core::control::{ControlStep, ValidatedConfig};
use model_core::Model;
use serde::Serialize;

use super::injection::Schedule;
use super::rig::{Command, Rig, Stepped};
use crate::numerics::metrics::{metrics, Metrics};
use crate::sim::plant::ClutchParams;

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
    let mut rig = Rig::new(clutch, &cfg, seed, fault);
    let mut ctrl = Stepped(step, step.state());
    let mut out = Run::default();
    for k in 0..n {
        let t = k as f64 * dt;
        let r = if t >= T_START { reference(t - T_START) } else { 0.0 };
        let s = rig.sample(&mut ctrl, &mut cfg, Command { reference: r, enable: true, reset: false });
        let o = s.out;
        out.t.push(s.t);
        out.reference.push(r);
        out.torque_est.push(f64::from(o.torque_est));
        out.torque_true.push(s.torque_true);
        out.load_cell.push(s.load_cell);
        out.b.push(f64::from(o.b));
        out.current.push(f64::from(o.current));
        out.coil_current.push(s.coil_current);
        out.i_ref.push(f64::from(o.i_ref));
        out.duty.push(s.applied.0);
        out.speed.push(s.speed);
        out.temperature.push(s.temperature);
        out.fault.push(o.fault.code());
        out.pwm_enable.push(s.applied.1);
    }
    out
}
