//! Frequency response of the true torque to stepped sines (gain |T/r| by a single-bin DFT
//! over whole periods) and the −3 dB bandwidth, Hz.

use model_core::control::{ControlStep, ValidatedConfig};
use model_core::Model;
use serde::Serialize;

use super::harness::{run, Run, T_START};
use crate::sim::plant::ClutchParams;

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
