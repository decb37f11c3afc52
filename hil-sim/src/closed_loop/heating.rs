//! Error drift as the fluid heats: per time window, the mean temperature (°C) and the mean
//! error (N·m) and R-RMSE of the true torque against the reference, for the loop, the loop
//! with temperature compensation and the baseline.

use serde::Serialize;

use super::harness::Run;
use crate::numerics::metrics::metrics;

/// Mean error (true torque − reference, N·m) and R-RMSE over a window.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct WindowError {
    pub mean_error: f64,
    pub r_rmse: f64,
}

/// One window of the heating run.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct HeatingWindow {
    /// Window start and end after the reference started, s.
    pub t0_s: u32,
    pub t1_s: u32,
    /// Mean fluid temperature of the loop run over the window, °C.
    pub temperature_c: f64,
    #[serde(rename = "loop")]
    pub closed_loop: WindowError,
    pub loop_temp_comp: WindowError,
    pub baseline: WindowError,
}

/// Error of `r` over `[max(t0, from), t1)` s, with the sample range.
fn window_error(r: &Run, t0: f64, t1: f64, from: f64) -> (WindowError, usize, usize) {
    let (k0, k1) = (r.after(t0.max(from)), r.after(t1));
    let e: f64 = (k0..k1).map(|k| r.torque_true[k] - r.reference[k]).sum::<f64>() / (k1 - k0) as f64;
    (WindowError { mean_error: e, r_rmse: metrics(&r.reference[k0..k1], &r.torque_true[k0..k1], None).r_rmse }, k0, k1)
}

/// `n` windows of `width` s from `t_start` s on (samples before `from` s left out), for the
/// loop `lp`, the compensated loop `lc` and the baseline `bl`.
pub fn heating_windows(
    lp: &Run,
    lc: &Run,
    bl: &Run,
    t_start: f64,
    from: f64,
    width: u32,
    n: u32,
) -> Vec<HeatingWindow> {
    (0..n)
        .map(|w| {
            let (t0, t1) = (t_start + f64::from(width * w), t_start + f64::from(width * (w + 1)));
            let (closed_loop, k0, k1) = window_error(lp, t0, t1, from);
            let (loop_temp_comp, _, _) = window_error(lc, t0, t1, from);
            let (baseline, _, _) = window_error(bl, t0, t1, from);
            let temperature_c = lp.temperature[k0..k1].iter().sum::<f64>() / (k1 - k0) as f64;
            HeatingWindow {
                t0_s: width * w,
                t1_s: width * (w + 1),
                temperature_c,
                closed_loop,
                loop_temp_comp,
                baseline,
            }
        })
        .collect()
}
