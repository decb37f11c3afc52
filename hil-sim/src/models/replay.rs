//! Replay through the no_std core in f32, one step per sample: any model by id over
//! samples ([`replay()`]), and a recording's channels with the error metrics
//! ([`replay_recording`]).

use model_core::{Estimator, Model, ParamError, Sample};
use serde::Serialize;
use thiserror::Error;

use crate::io::recording::{Channels, Recording};
use crate::models::{visit, RateSpec, Visit};
use crate::numerics::metrics::{try_metrics, Metrics, NoSamples};

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
    /// The input's rate and acceleration (central differences), for the metrics.
    #[serde(skip)]
    pub rates: (Vec<f64>, Vec<f64>),
    /// The samples scored (`lo..hi`: a delayed channel leaves the ends unscored).
    #[serde(skip)]
    pub scored: (usize, usize),
}

/// The metrics of several replays (the runs of a dataset) pooled: every run's scored samples.
pub fn pooled(reports: &[ReplayReport]) -> Result<Metrics, NoSamples> {
    let (mut y, mut m, mut dx, mut ddx) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for r in reports {
        let (lo, hi) = r.scored;
        let part = |v: &[f64]| v.get(lo..hi).unwrap_or(&[]).to_vec();
        y.extend(part(&r.measured));
        m.extend(part(&r.model_output));
        dx.extend(part(&r.rates.0));
        ddx.extend(part(&r.rates.1));
    }
    try_metrics(&y, &m, Some((&dx, &ddx)))
}

/// Replay `rec` through `model` with flat `params`, the input and the command read
/// `delays_s` later ([`crate::models::alignment`]; 0 for none). The recording is consumed:
/// its time and output channels move into the report, and the samples the core sees are made
/// one at a time, so a long recording is held once.
pub fn replay_recording(
    mut rec: Recording,
    ch: &Channels,
    model: &str,
    params: &[f32],
    rate: RateSpec,
    delays_s: (f64, f64),
) -> Result<ReplayReport, ReplayError> {
    rec.check_roles(ch)?;
    crate::quality::timing::check_time_unit(&ch.time, rec.time(&ch.time)?)?;
    let dt = rec.sample_interval(&ch.time)?;
    let time = rec.take_channel(&ch.time)?;
    let measured = rec.take_channel(&ch.output)?;
    let (x, u) = (rec.channel(&ch.input)?, ch.command.as_deref().map(|c| rec.channel(c)).transpose()?);
    let (d, d_u) = (delays_s.0 / dt, if u.is_some() { delays_s.1 / dt } else { 0.0 });
    crate::models::alignment::check(x.len(), dt, &[d, d_u])?;
    let shifted = (d != 0.0 || d_u != 0.0).then(|| crate::models::alignment::shift_channels(x, u, d, d_u));
    let (x, u) = match &shifted {
        Some((x, u)) => (x.as_slice(), u.as_deref()),
        None => (x, u),
    };
    // A gap in the time column restarts the core, as a new run does (a fixed-step model
    // cannot step across missing time), and no rate is taken across it.
    let starts: Vec<usize> =
        std::iter::once(0).chain(crate::io::recording::gaps(&time, dt).into_iter().map(|i| i + 1)).collect();
    let out = replay_made(model, params, dt as f32, rate, (x.len(), |i| sample_at(x, u, i)), &starts)?;
    let model_output: Vec<f64> = out.y.iter().map(|v| f64::from(*v)).collect();
    drop(out.y);
    // Rates for seed 001's E_x, E_ẋ: central differences of the input, within each stretch.
    let per_stretch = |v: &[f64]| -> Vec<f64> {
        if let [_] = starts.as_slice() {
            return crate::numerics::derivative::gradient(v, dt);
        }
        let ends = starts.iter().skip(1).copied().chain([v.len()]);
        starts.iter().zip(ends).flat_map(|(&a, b)| crate::numerics::derivative::gradient(&v[a..b], dt)).collect()
    };
    let dx = per_stretch(x);
    let ddx = per_stretch(&dx);
    // Samples whose shifted channels read past the recording's ends are not scored.
    let (lo, hi) = crate::models::alignment::covered(x.len(), &[d, d_u]);
    fn part(v: &[f64], (lo, hi): (usize, usize)) -> &[f64] {
        v.get(lo..hi).unwrap_or(&[])
    }
    let metrics = try_metrics(
        part(&measured, (lo, hi)),
        part(&model_output, (lo, hi)),
        Some((part(&dx, (lo, hi)), part(&ddx, (lo, hi)))),
    )?;
    Ok(ReplayReport {
        model: model.to_owned(),
        samples: x.len(),
        dt_s: dt,
        metrics,
        held: out.held,
        time,
        measured,
        model_output,
        rates: (dx, ddx),
        scored: (lo, hi),
    })
}

/// The sample the core sees at `i`: input `x` in f32, with the command `u` when there is one.
pub fn sample_at(x: &[f64], u: Option<&[f64]>, i: usize) -> Sample {
    let s = Sample::new(x.get(i).map_or(f32::NAN, |v| *v as f32));
    match u.and_then(|u| u.get(i)) {
        Some(uv) => s.with_command(*uv as f32),
        None => s,
    }
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
    (0..x.len()).map(|i| sample_at(x, u, i)).collect()
}

/// Why a replay could not start.
#[derive(Debug, Error)]
pub enum ReplayError {
    #[error(transparent)]
    Recording(#[from] crate::io::recording::RecordingError),
    #[error("unknown model `{0}` (see `hil-sim models`)")]
    UnknownModel(String),
    #[error(transparent)]
    TimeUnit(#[from] crate::quality::timing::TimeUnitError),
    #[error(transparent)]
    Delay(#[from] crate::models::alignment::DelayError),
    #[error("{0}")]
    NothingScored(#[from] NoSamples),
    #[error("model `{model}`: {source}")]
    Params { model: String, source: ParamError },
}

/// Result of running samples through the f32 core.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Replay {
    pub y: Vec<f32>,
    /// Samples whose output was held (non-finite input or overflow).
    pub held: usize,
}

/// A replay to run: the model's parameters and step, and where its samples come from (a
/// slice of [`Sample`]s, or channels made into samples one at a time).
struct Run<'a, F> {
    params: &'a [f32],
    dt: f32,
    rate: RateSpec,
    /// The stretches' starts, `0` first: the core restarts at each.
    starts: &'a [usize],
    len: usize,
    sample: F,
}

impl<F: Fn(usize) -> Sample> Visit for Run<'_, F> {
    type Out = Result<Replay, ParamError>;
    fn visit<M: Model>(self) -> Self::Out {
        let model = M::from_params(self.params, self.dt)?;
        let est = Estimator::new(model, self.rate.build(self.dt)?)?;
        let mut out = Replay { y: Vec::with_capacity(self.len), held: 0 };
        let bounds = self.starts.iter().copied().filter(|&s| s > 0 && s < self.len).chain([self.len]);
        let mut a = 0;
        for b in bounds {
            let mut st = est.state();
            for i in a..b {
                let o = est.step(&mut st, (self.sample)(i));
                out.held += usize::from(!o.flags.ok());
                out.y.push(o.y);
            }
            a = b;
        }
        Ok(out)
    }
}

/// Run `run` through model `id`.
fn dispatch<F: Fn(usize) -> Sample>(id: &str, run: Run<'_, F>) -> Result<Replay, ReplayError> {
    visit(id, run)
        .ok_or_else(|| ReplayError::UnknownModel(id.to_owned()))?
        .map_err(|source| ReplayError::Params { model: id.to_owned(), source })
}

/// Run `samples` through model `id` with flat parameters `params`, one step per sample
/// of `dt` seconds, in f32 — the code the firmware runs.
pub fn replay(id: &str, params: &[f32], dt: f32, rate: RateSpec, samples: &[Sample]) -> Result<Replay, ReplayError> {
    replay_runs(id, params, dt, rate, samples, &[0])
}

/// [`replay`] of a dataset whose runs start at `starts`: the core (state and rate
/// estimator) restarts at every run.
pub fn replay_runs(
    id: &str,
    params: &[f32],
    dt: f32,
    rate: RateSpec,
    samples: &[Sample],
    starts: &[usize],
) -> Result<Replay, ReplayError> {
    let sample = |i: usize| samples.get(i).copied().unwrap_or(Sample::new(f32::NAN));
    dispatch(id, Run { params, dt, rate, starts, len: samples.len(), sample })
}

/// [`replay_runs`] of `len` samples made by `sample` as the core steps (nothing held but
/// the output).
pub fn replay_made(
    id: &str,
    params: &[f32],
    dt: f32,
    rate: RateSpec,
    (len, sample): (usize, impl Fn(usize) -> Sample),
    starts: &[usize],
) -> Result<Replay, ReplayError> {
    dispatch(id, Run { params, dt, rate, starts, len, sample })
}

#[cfg(test)]
mod sample_tests {
    use super::*;

    #[test]
    fn every_registered_id_dispatches() {
        struct Id;
        impl Visit for Id {
            type Out = &'static str;
            fn visit<M: Model>(self) -> &'static str {
                M::ID
            }
        }
        for info in model_core::MODELS.iter() {
            assert_eq!(visit(info.id, Id), Some(info.id));
        }
        assert_eq!(visit("nope", Id), None);
    }

    #[test]
    fn algebraic_replay_and_errors() {
        let s: Vec<Sample> = (0..4).map(|i| Sample::new(i as f32)).collect();
        let r = replay("algebraic", &[2.0, 0.0, 0.0, 1.0], 0.01, RateSpec::Backward, &s).unwrap();
        assert_eq!(r.y, vec![1.0, 3.0, 5.0, 7.0]);
        assert!(matches!(replay("nope", &[], 0.01, RateSpec::Backward, &s), Err(ReplayError::UnknownModel(_))));
        let e = replay("algebraic", &[1.0], 0.01, RateSpec::Backward, &s).unwrap_err();
        assert!(e.to_string().contains("expected 4 parameters"), "{e}");
    }
}
