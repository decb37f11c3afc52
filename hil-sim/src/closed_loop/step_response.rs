//! Step response of the true torque: 10–90 % rise time (s) of each step of the reference,
//! measured from the torque just before the step to the new reference level.

use serde::Serialize;

use super::harness::Run;

/// 10–90 % rise time of the step of the reference at `t0` s, searched until `t1` s; `None`
/// when there is no step sample or the torque never crosses a level.
pub fn rise_time(r: &Run, t0: f64, t1: f64) -> Option<f64> {
    let (k0, k1) = (r.after(t0), r.after(t1));
    let (from, to) = (*r.reference.get(k0.checked_sub(1)?)?, *r.reference.get(k0)?);
    let y0 = r.torque_true.get(k0.checked_sub(1)?)?;
    let span = to - from;
    let lvl = |f: f64| y0 + f * (to - y0);
    let cross =
        |f: f64| (k0..k1).find(|&k| if span > 0.0 { r.torque_true[k] >= lvl(f) } else { r.torque_true[k] <= lvl(f) });
    Some((cross(0.9)? as f64 - cross(0.1)? as f64) * (r.t[1] - r.t[0]))
}

/// Rise times of the loop and the baseline at one step.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct StepRise {
    /// Step time after the reference started, s.
    pub at_s: f64,
    /// 10–90 % rise time of the closed loop, ms.
    pub loop_rise_ms: Option<f64>,
    /// 10–90 % rise time of the baseline, ms.
    pub baseline_rise_ms: Option<f64>,
}

/// Rise times at the steps `t_start + hold·j` for `j` in `steps` (each searched for one
/// `hold`, s), loop against baseline.
pub fn step_rises(lp: &Run, bl: &Run, t_start: f64, hold: f64, steps: std::ops::Range<usize>) -> Vec<StepRise> {
    steps
        .map(|j| {
            let t0 = t_start + hold * j as f64;
            StepRise {
                at_s: t0 - t_start,
                loop_rise_ms: rise_time(lp, t0, t0 + hold).map(|v| v * 1e3),
                baseline_rise_ms: rise_time(bl, t0, t0 + hold).map(|v| v * 1e3),
            }
        })
        .collect()
}
