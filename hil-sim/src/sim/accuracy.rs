//! How far the f32 one-step-per-sample core is from the continuous-time model.
//!
//! For every ODE model and published parameter set in [`crate::models::reference`], the f64
//! right-hand side is integrated with an adaptive 5th-order Dormand–Prince method
//! (`ode_solvers::Dopri5`, rtol 1e-10; not `Dop853`: in ode_solvers 0.6.2 it mishandles
//! time-dependent right-hand sides — thousands of steps per sample and errors in the 8th
//! digit on a smooth scalar ODE where Dopri5 agrees with itself across tolerances) across every sample interval, and compared with the
//! f32 core stepped once per sample. Synthetic excitations (seed 000's sines 1–9 Hz,
//! multi-sine eq. 21, swept-sine eq. 22) give the core the analytic input rate; the real
//! displacement of `ranran_50.csv` is treated as piecewise linear (the core then sees
//! the backward difference, which is the exact rate of that interpolation).

use std::path::Path;

use model_core::Sample;
use ode_solvers::dop_shared::OutputType;
use ode_solvers::{dopri5::Dopri5, DVector, System};
use rayon::prelude::*;
use serde::Serialize;
use thiserror::Error;

use crate::io::recording::Recording;
use crate::models::reference::{Case, Command, Input, Reference};
use crate::models::{replay, RateSpec};
use crate::progress::Progress;
use crate::sim::excitation::Excitation;

/// Why an accuracy run could not be made.
#[derive(Debug, Error)]
pub enum AccuracyError {
    /// The f64 reference could not be integrated.
    #[error("{0}")]
    Reference(String),
    #[error(transparent)]
    Replay(#[from] crate::models::ReplayError),
    #[error(transparent)]
    Recording(#[from] crate::io::recording::RecordingError),
    #[error("{model} [{label}]: {source}")]
    Case { model: String, label: String, source: Box<AccuracyError> },
}

/// The acceptance bound on the R-RMSE of the difference.
pub const MAX_R_RMSE: f64 = 0.005;

/// One model × parameter set × excitation × sampling rate.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    pub model: String,
    pub params: String,
    pub excitation: String,
    pub fs_hz: f64,
    pub samples: usize,
    /// R-RMSE (seed 000 eq. 20) of f32-core output minus f64 reference, against the reference.
    pub r_rmse: f64,
    /// Largest absolute difference, output units.
    pub max_abs_err: f64,
    /// Peak-to-peak of the reference output, output units.
    pub span: f64,
    /// Samples the core flagged and held (should be 0).
    pub held: usize,
    pub pass: bool,
}

struct Sys<'a, F: Fn(f64) -> Input> {
    model: &'a dyn Reference,
    input: F,
}

impl<F: Fn(f64) -> Input> System<f64, DVector<f64>> for Sys<'_, F> {
    fn system(&self, t: f64, y: &DVector<f64>, dy: &mut DVector<f64>) {
        let inp = (self.input)(t);
        self.model.rhs(y.as_slice(), &inp, dy.as_mut_slice());
    }
}

/// The reference solver: Dormand–Prince 5(4), rtol 1e-10, atol 1e-12, steps of at most
/// one sample period `dt` (so no reversal is stepped over unseen; dense output comes
/// every `dt`), stiffness detection off (some published sets are mildly stiff; an
/// explicit method with error control is still exact, only slower).
fn dopri5<'a, F: Fn(f64) -> Input>(
    sys: Sys<'a, F>,
    s0: &[f64],
    t0: f64,
    t1: f64,
    dt: f64,
    out: OutputType,
) -> Dopri5<f64, DVector<f64>, Sys<'a, F>> {
    Dopri5::from_param(
        sys,
        t0,
        t1,
        dt,
        DVector::from_column_slice(s0),
        1e-10,
        1e-12,
        0.9,
        0.0,
        0.2,
        10.0,
        dt,
        dt / 4.0,
        u32::MAX,
        u32::MAX,
        out,
    )
}

/// Integrate the reference from `t0` to `t1` with `input` valid on that interval.
fn advance<F: Fn(f64) -> Input>(
    model: &dyn Reference,
    s: &[f64],
    t0: f64,
    t1: f64,
    input: F,
) -> Result<Vec<f64>, AccuracyError> {
    let mut solver = dopri5(Sys { model, input }, s, t0, t1, t1 - t0, OutputType::Sparse);
    solver
        .integrate()
        .map_err(|e| AccuracyError::Reference(format!("reference integration failed at t = {t0}: {e}")))?;
    solver
        .y_out()
        .last()
        .map(|v| v.as_slice().to_vec())
        .ok_or_else(|| AccuracyError::Reference("reference integrator returned nothing".to_owned()))
}

/// Reference output at every sample for a smooth input: one adaptive run over the whole
/// signal, read at the sample instants from the method's dense output.
fn dense_outputs(
    model: &dyn Reference,
    n: usize,
    dt: f64,
    input_at: impl Fn(f64) -> Input,
) -> Result<Vec<f64>, AccuracyError> {
    let first = input_at(0.0);
    let s0 = model.init(&first);
    if s0.len() != model.dim() {
        return Err(AccuracyError::Reference(format!(
            "reference init gave {} states, dim() says {}",
            s0.len(),
            model.dim()
        )));
    }
    let t_end = (n - 1) as f64 * dt;
    let mut solver = dopri5(Sys { model, input: &input_at }, &s0, 0.0, t_end, dt, OutputType::Dense);
    solver.integrate().map_err(|e| AccuracyError::Reference(format!("reference integration failed: {e}")))?;
    let (ts, ys) = (solver.x_out(), solver.y_out());
    if ts.len() < n {
        return Err(AccuracyError::Reference(format!("dense output gave {} of {n} samples", ts.len())));
    }
    Ok(ts.iter().zip(ys).take(n).map(|(t, y)| model.output(y.as_slice(), &input_at(*t))).collect())
}

/// Reference output at every sample for inputs given per interval.
fn reference_outputs(
    model: &dyn Reference,
    n: usize,
    dt: f64,
    at: impl Fn(usize) -> Input,
    on_interval: impl Fn(usize, f64) -> Input + Sync,
) -> Result<Vec<f64>, AccuracyError> {
    let first = at(0);
    let mut s = model.init(&first);
    if s.len() != model.dim() {
        return Err(AccuracyError::Reference(format!(
            "reference init gave {} states, dim() says {}",
            s.len(),
            model.dim()
        )));
    }
    let mut out = Vec::with_capacity(n);
    out.push(model.output(&s, &first));
    for k in 1..n {
        let (t0, t1) = ((k - 1) as f64 * dt, k as f64 * dt);
        s = advance(model, &s, t0, t1, |t| on_interval(k, t))?;
        out.push(model.output(&s, &at(k)));
    }
    Ok(out)
}

fn compare(case: &Case, excitation: String, fs: f64, core: &[f32], held: usize, r: &[f64]) -> Row {
    let y: Vec<f64> = core.iter().map(|v| f64::from(*v)).collect();
    let r_rmse = crate::numerics::metrics::r_rmse(r, &y);
    let max_abs_err = y.iter().zip(r).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    let (lo, hi) = r.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(*v), h.max(*v)));
    Row {
        model: case.model.to_owned(),
        params: case.label.clone(),
        excitation,
        fs_hz: fs,
        samples: r.len(),
        r_rmse,
        max_abs_err,
        span: hi - lo,
        held,
        pass: r_rmse.is_finite() && r_rmse <= MAX_R_RMSE && held == 0,
    }
}

/// Check one case on a synthetic excitation of `duration` seconds sampled at `fs` Hz.
pub fn synthetic(case: &Case, exc: &Excitation, fs: f64, duration: f64) -> Result<Row, AccuracyError> {
    let dt = 1.0 / fs;
    let n = (duration * fs).round() as usize + 1;
    let u = match case.command {
        Command::None => 0.0,
        Command::Constant(u) => u,
    };
    let (a, b) = (case.scale.amplitude, case.scale.offset);
    let input_at = |t: f64| {
        let p = exc.at(t);
        Input { x: b + a * p.x, dx: a * p.dx, ddx: a * p.ddx, u }
    };
    let samples: Vec<Sample> = (0..n)
        .map(|k| {
            let i = input_at(k as f64 * dt);
            let s = Sample { x: i.x as f32, u: None, dx: Some(i.dx as f32), ddx: Some(i.ddx as f32) };
            if matches!(case.command, Command::Constant(_)) {
                s.with_command(u as f32)
            } else {
                s
            }
        })
        .collect();
    let core = replay(case.model, &case.params, dt as f32, RateSpec::Backward, &samples)?;
    let r = dense_outputs(case.reference.as_ref(), n, dt, input_at)?;
    Ok(compare(case, exc.name(), fs, &core.y, core.held, &r))
}

/// Check one case on the real displacement `D` (cm) and command `Y` (V) of a Dyke
/// recording, at its own sampling rate.
pub fn dyke(case: &Case, rec: &Recording) -> Result<Row, AccuracyError> {
    let x = rec.channel("D")?;
    let u = rec.channel("Y")?;
    let dt = rec.sample_interval("t")?;
    let n = x.len();
    let samples: Vec<Sample> = x.iter().zip(u).map(|(x, u)| Sample::new(*x as f32).with_command(*u as f32)).collect();
    let core = replay(case.model, &case.params, dt as f32, RateSpec::Backward, &samples)?;
    // The f32 core sees x and u in f32: give the reference the same rounded values.
    let xf: Vec<f64> = x.iter().map(|v| f64::from(*v as f32)).collect();
    let uf: Vec<f64> = u.iter().map(|v| f64::from(*v as f32)).collect();
    let slope = |k: usize| (xf[k] - xf[k - 1]) / dt;
    let r = reference_outputs(
        case.reference.as_ref(),
        n,
        dt,
        |k| Input { x: xf[k], dx: if k > 0 { slope(k) } else { 0.0 }, ddx: 0.0, u: uf[k] },
        |k, t| {
            // Input and command linear between samples: the f32 core's η filter is exact
            // for a command of that shape, and its rate is the backward difference.
            let s = (t - (k - 1) as f64 * dt) / dt;
            let u = uf[k - 1] + (uf[k] - uf[k - 1]) * s;
            Input { x: xf[k - 1] + slope(k) * s * dt, dx: slope(k), ddx: 0.0, u }
        },
    )?;
    let name = format!(
        "recording {} (D, Y)",
        rec.path.file_name().map_or_else(|| "?".into(), |f| f.to_string_lossy().into_owned())
    );
    Ok(compare(case, name, 1.0 / dt, &core.y, core.held, &r))
}

/// The excitations of the check, with their durations in seconds.
pub fn excitations(quick: bool) -> Vec<(Excitation, f64)> {
    let scale = if quick { 0.25 } else { 1.0 };
    let mut v: Vec<(Excitation, f64)> =
        [1.0, 3.0, 5.0, 7.0, 9.0].iter().map(|f| (Excitation::Sine { f: *f }, 2.0)).collect();
    v.push((Excitation::seed000_multisine(), 10.0 * scale));
    v.push((Excitation::seed000_swept(40.0), 40.0 * scale));
    v
}

/// Sampling rates of the check: the papers' range.
pub const RATES_HZ: [f64; 2] = [500.0, 3000.0];

/// Run the whole check (in parallel); `dyke` is the recording used for the damper cases.
/// `filter` keeps only cases of one model. `progress` is called after each row.
pub fn run_all(
    filter: Option<&str>,
    quick: bool,
    dyke_recording: Option<&Recording>,
    progress: &dyn Progress,
) -> Result<Vec<Row>, AccuracyError> {
    let cases: Vec<Case> =
        crate::models::reference::cases().into_iter().filter(|c| filter.is_none_or(|f| c.model == f)).collect();
    // (case index, synthetic excitation with duration and rate, or the recording)
    type Job = (usize, Option<(Excitation, f64, f64)>);
    let mut jobs: Vec<Job> = Vec::new();
    for (i, c) in cases.iter().enumerate() {
        for (e, d) in excitations(quick) {
            for fs in RATES_HZ {
                jobs.push((i, Some((e.clone(), d, fs))));
            }
        }
        if c.on_dyke_recording && dyke_recording.is_some() {
            jobs.push((i, None));
        }
    }
    jobs.par_iter()
        .map(|(i, job)| {
            let case = &cases[*i];
            let row = match (job, dyke_recording) {
                (Some((e, d, fs)), _) => synthetic(case, e, *fs, *d),
                (None, Some(rec)) => dyke(case, rec),
                (None, None) => Err(AccuracyError::Reference("no recording".into())),
            };
            progress.advance(1);
            row.map_err(|e| AccuracyError::Case {
                model: case.model.to_owned(),
                label: case.label.clone(),
                source: Box::new(e),
            })
        })
        .collect()
}

/// Number of rows [`run_all`] will produce.
pub fn count_jobs(filter: Option<&str>, quick: bool, with_dyke: bool) -> usize {
    crate::models::reference::cases()
        .iter()
        .filter(|c| filter.is_none_or(|f| c.model == f))
        .map(|c| excitations(quick).len() * RATES_HZ.len() + usize::from(c.on_dyke_recording && with_dyke))
        .sum()
}

/// Read the Dyke recording used by the damper cases.
pub fn load_dyke(path: &Path) -> Result<Recording, AccuracyError> {
    Ok(Recording::read_csv(path)?)
}
