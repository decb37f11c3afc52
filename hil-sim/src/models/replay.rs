//! Replay a recording through the no_std core in f32, one step per sample.

use model_core::Sample;
use serde::Serialize;

use crate::io::recording::Recording;
use crate::models::{replay, RateChoice};
use crate::numerics::metrics::{metrics, Metrics};

/// Which columns play which role.
#[derive(Clone, Debug, PartialEq)]
pub struct Channels {
    pub time: String,
    pub input: String,
    pub output: String,
    /// Channel driving current/voltage-dependent parameters, if any.
    pub command: Option<String>,
}

impl Default for Channels {
    /// The contract's defaults for an MR clutch: `t`, `b`, `torque`.
    fn default() -> Self {
        Self { time: "t".into(), input: "b".into(), output: "torque".into(), command: None }
    }
}

/// What a replay measured.
#[derive(Clone, Debug, Serialize)]
pub struct ReplayReport {
    pub model: String,
    pub samples: usize,
    pub dt_s: f64,
    pub metrics: Metrics,
    /// Samples whose output the core held (non-finite input or overflow).
    pub held: usize,
    #[serde(skip)]
    pub time: Vec<f64>,
    #[serde(skip)]
    pub measured: Vec<f64>,
    #[serde(skip)]
    pub model_output: Vec<f64>,
}

/// Replay `rec` through `model` with flat `params`, the input and the command read
/// `delays_s` later ([`crate::ident::alignment`]; 0 for none); errors are one line of text.
pub fn replay_recording(
    rec: &Recording,
    ch: &Channels,
    model: &str,
    params: &[f32],
    rate: RateChoice,
    delays_s: (f64, f64),
) -> anyhow::Result<ReplayReport> {
    let t = rec.time(&ch.time)?;
    let x = rec.channel(&ch.input)?;
    let y = rec.channel(&ch.output)?;
    let u = ch.command.as_deref().map(|c| rec.channel(c)).transpose()?;
    let dt = rec.mean_dt(&ch.time)?;
    let (d, d_u) = (delays_s.0 / dt, if u.is_some() { delays_s.1 / dt } else { 0.0 });
    let (x, u) = crate::ident::alignment::shift_channels(x, u, d, d_u);
    let samples = samples(&x, u.as_deref());
    let out = replay(model, params, dt as f32, rate, &samples)?;
    let model_output: Vec<f64> = out.y.iter().map(|v| f64::from(*v)).collect();
    // Rates for seed 001's E_x, E_ẋ: central differences of the input.
    let dx = gradient(&x, dt);
    let ddx = gradient(&dx, dt);
    // Samples whose shifted channels read past the recording's ends are not scored.
    let (lo, hi) = crate::ident::alignment::covered(x.len(), &[d, d_u]);
    let part = |v: &[f64]| v.get(lo..hi).unwrap_or(&[]).to_vec();
    Ok(ReplayReport {
        model: model.to_owned(),
        samples: x.len(),
        dt_s: dt,
        metrics: metrics(&part(y), &part(&model_output), Some((&part(&dx), &part(&ddx)))),
        held: out.held,
        time: t.to_vec(),
        measured: y.to_vec(),
        model_output,
    })
}

/// The samples the core sees: input `x` in f32, with the command `u` when there is one.
/// [`samples`] with a given rate and acceleration of the input attached (the core then uses
/// them instead of its rate estimator's).
pub fn samples_with_rates(x: &[f64], u: Option<&[f64]>, rates: Option<&(Vec<f64>, Vec<f64>)>) -> Vec<Sample> {
    let mut s = samples(x, u);
    if let Some((dx, ddx)) = rates {
        for ((s, d), dd) in s.iter_mut().zip(dx).zip(ddx) {
            s.dx = Some(*d as f32);
            s.ddx = Some(*dd as f32);
        }
    }
    s
}

pub fn samples(x: &[f64], u: Option<&[f64]>) -> Vec<Sample> {
    x.iter()
        .enumerate()
        .map(|(i, xv)| {
            let s = Sample::new(*xv as f32);
            match u.and_then(|u| u.get(i)) {
                Some(uv) => s.with_command(*uv as f32),
                None => s,
            }
        })
        .collect()
}

/// Central-difference derivative (one-sided at the ends).
pub fn gradient(v: &[f64], dt: f64) -> Vec<f64> {
    let n = v.len();
    (0..n)
        .map(|i| match (i.checked_sub(1).and_then(|j| v.get(j)), v.get(i + 1)) {
            (Some(a), Some(b)) => (b - a) / (2.0 * dt),
            (None, Some(b)) => (b - v[i]) / dt,
            (Some(a), None) => (v[i] - a) / dt,
            (None, None) => 0.0,
        })
        .collect()
}
