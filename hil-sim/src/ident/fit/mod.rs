//! Identification: fit any model's parameters to a recording, with the exact f32 core the
//! firmware runs, and score the result on held-out data.
//!
//! - [`Dataset`]: one recording's input, output and command, the time-ordered train /
//!   held-out split and the samples the quality checks flagged.
//! - Each model's search box, starting values (from the papers, rescaled to the
//!   recording's units) and method are in its host file ([`crate::models::HostModel`]).
//! - Methods: closed-form least squares ([`linear`]) where the model is linear in its
//!   parameters; for the models with local minima, a small particle swarm ([`global`])
//!   on a window of the training part, bounded Levenberg–Marquardt ([`lm`]) polishing its
//!   best points, the papers' starting values and, for a model affine in some of its
//!   parameters, the best points of a grid over the others ([`separable`]) on that window, and a final
//!   Levenberg–Marquardt run on the whole training part from the candidate that scores best
//!   there.
//! - [`job`] runs `hil-sim fit` as one call (read, check, fit with progress, save).
//! - [`fit`] returns the parameters and all metrics of the contract, train and held-out,
//!   from a replay through [`crate::models::replay()`] — the `Estimator` path, f32.

pub mod confidence;
mod delays;
pub mod global;
pub mod hold;
pub mod identifiable;
pub mod job;
pub mod linear;
pub mod lm;
pub mod narx;
pub mod narx_net;
pub mod objective;
pub mod operator;
mod per_run;
pub mod restarts;
pub mod separable;
pub mod simulate;
mod warm;

use std::time::Instant;

use serde::Serialize;
use thiserror::Error;

use crate::io::params_file::{ParamsFile, Values};
use crate::models::search::{ModelSpec, Scales, Strategy, Structure};
use crate::models::RateSpec;
use crate::numerics::derivative::gradient;
use crate::numerics::metrics::{metrics_at, Metrics};
use global::SwarmOptions;

pub use crate::ident::dataset::{Dataset, DatasetError};
use delays::scan_delay;
use objective::Objective;
use per_run::per_run_metrics;
pub use per_run::RunMetrics;
use warm::{projected_shape, warm_fit};

/// Both parts keep samples to score under the delays `ds` (samples, step `dt` s).
fn scored_parts(train: &[usize], heldout: &[usize], ds: (f64, f64), dt: f64) -> Result<(), FitError> {
    for (part, r) in [("training", train), ("held-out", heldout)] {
        if r.is_empty() {
            let delay_s = if ds.0.abs() >= ds.1.abs() { ds.0 } else { ds.1 } * dt;
            return Err(FitError::NothingScored { part, delay_s });
        }
    }
    Ok(())
}

/// Why a fit could not run.
#[derive(Debug, Error)]
pub enum FitError {
    #[error(transparent)]
    Dataset(#[from] DatasetError),
    #[error("unknown model `{0}` (see `hil-sim models`)")]
    UnknownModel(String),
    #[error("model `{0}` is not fitted by this build")]
    NotFittable(String),
    #[error("{model}: the rate estimate overflows on this input")]
    RateOverflow { model: String },
    #[error("{model}: no valid parameter set found in the search box")]
    NoValidSet { model: String },
    #[error("{model}: swarm search failed: {reason}")]
    Swarm { model: String, reason: String },
    #[error("{model}: replay of the fitted set failed: {reason}")]
    Replay { model: String, reason: String },
    #[error(transparent)]
    Delay(#[from] crate::models::alignment::DelayError),
    #[error("the {part} part has no sample left to score with a delay of {delay_s} s")]
    NothingScored { part: &'static str, delay_s: f64 },
}

/// Whether the fit aligns the input channel with the output ([`crate::models::alignment`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DelayChoice {
    /// No shift: the channels are taken as recorded.
    Off,
    /// Fit the delays with the model's parameters (within ±8 samples): the input's, and the
    /// command's when there is a command channel (the closed-form models fit the input's only).
    Auto,
    /// Known delays, seconds: input, command.
    Fixed(f64, f64),
}

/// How hard to search.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FitOptions {
    /// Rate estimator for every model (`None`: each model's preferred one).
    pub rate: Option<RateSpec>,
    /// Input delay: fitted (default), off, or given.
    pub delay: DelayChoice,
    pub swarm: SwarmOptions,
    /// Samples of the training part the swarm scores (the start of it), to keep the global
    /// phase cheap; Levenberg–Marquardt then uses the whole training part.
    pub swarm_window: usize,
    /// Iterations (Jacobians) allowed to the final Levenberg–Marquardt run on the whole
    /// training part (and to the local and linear strategies).
    pub lm_iterations: usize,
    /// Iterations allowed to polishing each candidate (the swarm's and the papers' start) on
    /// the window.
    ///
    /// The defaults (10 and 12) are set for real, noisy recordings within the time budget of
    /// issue 3 (Spencer's model on 63k samples in 2 s); noiseless synthetic data, whose cost
    /// goes to zero, needs more to converge to its truth.
    pub polish_iterations: usize,
    /// Whether the global search also starts from the separable grid ([`separable`]) of a
    /// model with affine parameters (on by default).
    pub separable: bool,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            rate: None,
            delay: DelayChoice::Auto,
            swarm: SwarmOptions::default(),
            swarm_window: 9_000,
            lm_iterations: 10,
            polish_iterations: 12,
            separable: true,
        }
    }
}

/// One model's result, in the contract's shape (`model, params, train, heldout, fit_seconds`).
#[derive(Clone, Debug, Serialize)]
pub struct FitResult {
    pub model: String,
    /// Fitted parameters by name (blocks as arrays).
    pub params: Values,
    /// Input delay the model is fed with, seconds (`x(t + delay_s)`; 0 when not fitted).
    pub delay_s: f64,
    /// Command delay, seconds (`u(t + command_delay_s)`; 0 without a command or a fit).
    pub command_delay_s: f64,
    /// On the training samples the fit used (flagged ones left out).
    pub train: Metrics,
    /// On every held-out sample.
    pub heldout: Metrics,
    /// On the held-out samples the quality checks did not flag, when some were flagged.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub heldout_unflagged: Option<Metrics>,
    pub fit_seconds: f64,
    pub method: Strategy,
    /// Rate estimator used (`backward`, `filtered:FC`, `kalman:Q:R`).
    pub rate: String,
    /// Model evaluations over the training data.
    pub evaluations: usize,
    /// Wall time of the f32 replay per sample, nanoseconds.
    pub replay_ns_per_sample: f64,
    pub n_params: usize,
    pub free_params: usize,
    pub state_bytes: usize,
    /// Samples whose output the core held (non-finite or overflow) in the replay.
    pub held: usize,
    /// Each run's metrics, for a dataset of several recordings (empty for one).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub runs: Vec<RunMetrics>,
    /// What the fit noticed about the fitted set (e.g. a non-physical crossing loop of the
    /// asymmetric Bouc–Wen model, seed 004 on eq. 30).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// Parameters the data cannot tell from zero, held at zero ([`hold`]), by name.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub held_params: Vec<String>,
    /// Flat parameter vector (registry order).
    #[serde(skip)]
    pub flat: Vec<f64>,
    #[serde(skip)]
    pub rate_choice: RateSpec,
    /// The variant of the model's search the parameters belong to
    /// ([`crate::models::HostModel::variant`]; 0: the model's spec).
    #[serde(skip)]
    pub variant: usize,
    /// The replayed output over the whole recording.
    #[serde(skip)]
    pub output: Vec<f64>,
}

/// Fit model `id` to `data`. A fitted delay that ends at the edge of its search range is
/// held at zero and the model refitted from the first search's parameters, with a warning
/// ([`identifiable`]); a parameter whose confidence interval spans zero is held at zero
/// when holding it costs little ([`hold`]).
pub fn fit(id: &str, data: &Dataset, opts: &FitOptions) -> Result<FitResult, FitError> {
    let first = search(id, data, opts, None)?;
    let dt = data.dt;
    let (d, d_u) = first.delays;
    let (edge_x, edge_u) = (identifiable::at_edge(d), identifiable::at_edge(d_u));
    if opts.delay != DelayChoice::Auto || !(edge_x || edge_u) {
        return finish(id, data, opts, first, None);
    }
    let mut which = Vec::new();
    if edge_x {
        which.push(("input", d));
    }
    if edge_u {
        which.push(("command", d_u));
    }
    // The first search is not finished (scored, checked): its delays are discarded, its
    // parameters are where the refit starts (a second global search cost as much as the first).
    let held = DelayChoice::Fixed(if edge_x { 0.0 } else { d * dt }, if edge_u { 0.0 } else { d_u * dt });
    // Only the first search's parameters go on: its kinematics are released before the
    // refit builds its own.
    let Searched { params, variant, seconds, evaluations, .. } = first;
    let mut r = search(id, data, &FitOptions { delay: held, ..*opts }, Some((&params, variant)))?;
    r.seconds += seconds;
    r.evaluations += evaluations;
    finish(id, data, opts, r, Some(identifiable::edge_warning(&which, dt)))
}

/// What [`search`] found, for [`finish`] to check and score.
struct Searched {
    sp: ModelSpec,
    scales: Scales,
    sim: Box<dyn simulate::Simulator>,
    starts: Vec<usize>,
    kin: Vec<model_core::Kin>,
    rows: Vec<usize>,
    constant_u: Option<f64>,
    /// The model's parameters (no delay entries), the evaluations spent, the variant of the
    /// search they come from, the delays (samples).
    params: Vec<f64>,
    evaluations: usize,
    variant: usize,
    delays: (f64, f64),
    notes: Vec<String>,
    seconds: f64,
}

/// The search of [`fit`] under `opts.delay`, without the checks and the scores; from `warm`
/// (the model's parameters and their variant) by a local search when given ([`warm_fit`]).
fn search(id: &str, data: &Dataset, opts: &FitOptions, warm: Option<(&[f64], usize)>) -> Result<Searched, FitError> {
    // A command that never changes cannot identify the terms it drives: fit the model's
    // no-command form (those terms held) and say so.
    let constant_u = identifiable::constant_command(data);
    let scales = Scales { u: data.scales().u.filter(|_| constant_u.is_none()), ..data.scales() };
    let host = crate::models::host(id).ok_or_else(|| FitError::UnknownModel(id.to_owned()))?;
    let sp = host.spec(&scales, opts.rate).ok_or_else(|| FitError::NotFittable(id.to_owned()))?;
    let started = Instant::now();
    let dt = data.dt as f32;
    let starts = data.run_starts();
    let seen = delays::Seen::of(data, (0.0, 0.0), &starts);
    let kin = simulate::kinematics_of((0..data.len()).map(|i| seen.sample(i)), dt, sp.rate, &starts)
        .ok_or(FitError::RateOverflow { model: id.to_owned() })?;
    let sim = simulate::simulator_runs(id, dt, &starts).ok_or_else(|| FitError::UnknownModel(id.to_owned()))?;
    let rows = data.train_rows();
    let notes = restarts::Notes::default();
    let fit_at = |kin: &[model_core::Kin], sp: &ModelSpec| match warm {
        Some(w) => warm_fit(id, sp, w, sim.as_ref(), (kin, &data.output, &rows), &scales, opts, &notes),
        None => identify_variants(id, sp, sim.as_ref(), kin, &data.output, &rows, &scales, opts, &notes),
    };
    let n_model = sim.n_params();
    let (found, delays) = match (opts.delay, sp.strategy) {
        (DelayChoice::Off, _) => (fit_at(&kin, &sp)?, (0.0, 0.0)),
        (DelayChoice::Fixed(s, s_u), _) => {
            let d = (s / data.dt, if data.command.is_some() { s_u / data.dt } else { 0.0 });
            crate::models::alignment::check(data.len(), data.dt, &[d.0, d.1])?;
            let mut shifted = Vec::new();
            crate::models::alignment::shift_kin_runs(&kin, d.0, d.1, &starts, &mut shifted);
            (fit_at(&shifted, &sp)?, d)
        }
        // A network has past inputs for the lags it needs.
        (DelayChoice::Auto, Strategy::Network) => (fit_at(&kin, &sp)?, (0.0, 0.0)),
        (DelayChoice::Auto, Strategy::Linear | Strategy::Operator) => {
            let found = scan_delay(&kin, &starts, |k| {
                let r = fit_at(k, &sp).ok()?;
                let cost = Objective::new(sim.as_ref(), &sp, k, &data.output, &rows, scales.y).cost(&r.params);
                Some((r, cost))
            })
            .ok_or_else(|| FitError::NoValidSet { model: id.to_owned() })?;
            (found.0, (found.1, 0.0))
        }
        (DelayChoice::Auto, _) => {
            let spd = sp.clone().with_delays(
                data.command.is_some() && uses_command(id, &scales),
                crate::models::alignment::MAX_DELAY_SAMPLES,
            );
            let r = fit_at(&kin, &spd)?;
            let d = (r.params.get(n_model).copied().unwrap_or(0.0), r.params.get(n_model + 1).copied().unwrap_or(0.0));
            (r, d)
        }
    };
    let Identified { mut params, evaluations, variant } = found;
    params.truncate(n_model);
    let notes = notes.into_inner().unwrap_or_default();
    let seconds = started.elapsed().as_secs_f64();
    Ok(Searched {
        sp,
        scales,
        sim,
        starts,
        kin,
        rows,
        constant_u,
        params,
        evaluations,
        variant,
        delays,
        notes,
        seconds,
    })
}

/// Check what [`search`] found (what the data cannot determine held, [`hold`]) and score it;
/// `first_warning` goes first.
fn finish(
    id: &str,
    data: &Dataset,
    opts: &FitOptions,
    found: Searched,
    first_warning: Option<String>,
) -> Result<FitResult, FitError> {
    let info = model_core::registry::find(id).ok_or_else(|| FitError::UnknownModel(id.to_owned()))?;
    let Searched { sp, scales, sim, starts, kin, rows, constant_u, mut params, mut evaluations, .. } = found;
    // The variant the search kept: its held values and box, not the model's spec's.
    let variant = found.variant;
    let sp = crate::models::host(id).and_then(|h| h.at_variant(&sp, variant, &scales)).unwrap_or(sp);
    let (delay, delay_u) = found.delays;
    let started = Instant::now();
    let dt = data.dt as f32;
    let mut warnings: Vec<String> = first_warning.into_iter().collect();
    warnings.extend(identifiable::constant_command_note(id, data, constant_u));
    warnings.extend(found.notes);
    let ds = (delay, delay_u);
    let mut held_params = Vec::new();
    let mut confidence_warning = None;
    if matches!(sp.strategy, Strategy::Global | Strategy::Local) {
        let (y, sc, lm_iter) = (&data.output, scales.y, opts.lm_iterations);
        let f = hold::Fitted {
            sim: sim.as_ref(),
            spec: &sp,
            kin: &kin,
            y,
            rows: &rows,
            scale: sc,
            delays: ds,
            starts: &starts,
            params: &params,
        };
        let r = hold::resolve(&f, lm_iter);
        (params, held_params, confidence_warning) = (r.params, r.held, r.warning);
        evaluations += r.evaluations;
    }
    if sp.structure == Structure::AsymmetricBoucWen {
        warnings.extend(operator::abw_warning(&params, dt, &kin, ds, &starts, &rows));
    }
    warnings.extend(confidence_warning);
    drop(kin);
    let fit_seconds = found.seconds + started.elapsed().as_secs_f64();

    // Score with the Estimator path, the firmware's code, over the whole recording.
    let p32: Vec<f32> = params.iter().map(|v| *v as f32).collect();
    let seen = delays::Seen::of(data, (delay, delay_u), &starts);
    let t0 = Instant::now();
    let rep = crate::models::replay::replay_made(id, &p32, dt, sp.rate, (data.len(), |i| seen.sample(i)), &starts)
        .map_err(|e| FitError::Replay { model: id.to_owned(), reason: e.to_string() })?;
    let replay_ns = t0.elapsed().as_secs_f64() * 1e9 / data.len().max(1) as f64;
    let output: Vec<f64> = rep.y.iter().map(|v| f64::from(*v)).collect();
    drop(rep.y);
    let dx = data.per_run(&seen.input, |v| gradient(v, data.dt));
    let ddx = data.per_run(&dx, |v| gradient(v, data.dt));
    drop(seen);
    let score = |rows: &[usize]| metrics_at(rows, &data.output, &output, Some((&dx, &ddx)));
    // A delayed channel has no data for the first or last few samples of a run: those are not scored.
    let ds = [delay, delay_u];
    let unflagged = data.covered(&data.heldout_unflagged(), &ds);
    let all_heldout = data.covered(&data.heldout_rows(), &ds);
    let rows = data.covered(&rows, &ds);
    scored_parts(&rows, &all_heldout, (delay, delay_u), data.dt)?;
    let runs = per_run_metrics(data, &rows, &all_heldout, &score);
    let named = ParamsFile::from_flat(id, None, &p32).map(|f| f.params).unwrap_or(Values::Flat(params.clone()));
    Ok(FitResult {
        model: id.to_owned(),
        params: named,
        delay_s: delay * data.dt,
        command_delay_s: delay_u * data.dt,
        train: score(&rows),
        heldout: score(&all_heldout),
        heldout_unflagged: (unflagged.len() != all_heldout.len()).then(|| score(&unflagged)),
        fit_seconds,
        method: sp.strategy,
        rate: crate::io::rate::label(sp.rate),
        evaluations,
        replay_ns_per_sample: replay_ns,
        n_params: info.n_params,
        free_params: (sp.free().len() + operator::projected_count(sp.structure)).saturating_sub(held_params.len()),
        state_bytes: info.state_bytes,
        held: rep.held,
        runs,
        warnings,
        held_params,
        flat: params,
        rate_choice: sp.rate,
        variant,
        output,
    })
}

/// Whether model `id` has a command-dependent parameter the fit frees (its spec fixes more
/// parameters when the recording has no command channel).
fn uses_command(id: &str, scales: &Scales) -> bool {
    let free = |s: &Scales| crate::models::host(id).and_then(|h| h.spec(s, None)).map_or(0, |sp| sp.free().len());
    free(&Scales { u: None, ..*scales }) < free(scales)
}

/// A search's result: parameters, model evaluations spent, and which variant of the search
/// ([`crate::models::HostModel::variant`], 0: the model's spec) they belong to.
struct Identified {
    params: Vec<f64>,
    evaluations: usize,
    variant: usize,
}

/// [`identify`] for every variant of the search ([`crate::models::HostModel::variant`]); the lowest training
/// cost wins.
#[allow(clippy::too_many_arguments)]
fn identify_variants(
    id: &str,
    sp: &ModelSpec,
    sim: &dyn simulate::Simulator,
    kin: &[model_core::Kin],
    y: &[f64],
    rows: &[usize],
    scales: &Scales,
    opts: &FitOptions,
    notes: &restarts::Notes,
) -> Result<Identified, FitError> {
    let mut best: Option<(Vec<f64>, usize, f64)> = None;
    let mut evals = 0;
    let mut first_err = None;
    let mut k = 0;
    let mut current = Some(sp.clone());
    while let Some(v) = current {
        match identify(id, &v, sim, kin, y, rows, scales.y, opts, notes) {
            Ok((p, e)) => {
                evals += e;
                let cost = Objective::new(sim, &v, kin, y, rows, scales.y).cost(&p);
                if best.as_ref().is_none_or(|b| cost < b.2) {
                    best = Some((p, k, cost));
                }
            }
            Err(e) => first_err = first_err.or(Some(e)),
        }
        k += 1;
        current = crate::models::host(sp.id).and_then(|h| h.variant(sp, k, scales));
    }
    match (best, first_err) {
        (Some((params, variant, _)), _) => Ok(Identified { params, evaluations: evals, variant }),
        (None, Some(e)) => Err(e),
        (None, None) => Err(FitError::NoValidSet { model: id.to_owned() }),
    }
}

/// The search itself: returns the parameters and the number of model evaluations.
#[allow(clippy::too_many_arguments)]
fn identify(
    id: &str,
    sp: &ModelSpec,
    sim: &dyn simulate::Simulator,
    kin: &[model_core::Kin],
    y: &[f64],
    rows: &[usize],
    y_scale: f64,
    opts: &FitOptions,
    notes: &restarts::Notes,
) -> Result<(Vec<f64>, usize), FitError> {
    let full = Objective::new(sim, sp, kin, y, rows, y_scale);
    match sp.strategy {
        Strategy::Linear => {
            let p = linear::solve(id, kin, y, rows, &sp.free(), &sp.start())
                .ok_or_else(|| FitError::NoValidSet { model: id.to_owned() })?;
            if sim.valid(p.get(..sim.n_params()).unwrap_or(&p)) {
                return Ok((p, 1));
            }
            // A sign bound is active: continue from the box-clamped solution under LM.
            let clamped: Vec<f64> = p.iter().zip(&sp.params).map(|(v, ps)| v.clamp(ps.lo, ps.hi)).collect();
            let r = lm::minimize(&full, &clamped, opts.lm_iterations);
            valid_or_err(id, sim, r.params, r.evaluations + 1)
        }
        Strategy::Local => {
            let r = lm::minimize(&full, &sp.start(), opts.lm_iterations);
            valid_or_err(id, sim, r.params, r.evaluations)
        }
        Strategy::Operator => {
            let n_ops = (sim.n_params().saturating_sub(2)) / 2;
            let (mut p, _) = operator::closed_form(sp.structure, n_ops, kin, y, rows)
                .ok_or_else(|| FitError::NoValidSet { model: id.to_owned() })?;
            // Delay entries, if the spec carries them, stay at their (zero) start.
            p.extend(sp.start().get(sim.n_params()..).unwrap_or(&[]).iter().copied());
            valid_or_err(id, sim, p, 1)
        }
        Strategy::Projected => {
            let proj = operator::Projected::new(sim, y, rows).ok_or_else(|| FitError::NotFittable(id.to_owned()))?;
            let shape = projected_shape(sp, kin, rows);
            let (p, evals) = identify(id, &shape, &proj, kin, y, rows, y_scale, opts, notes)?;
            let full = proj.complete(&p, kin).ok_or_else(|| FitError::NoValidSet { model: id.to_owned() })?;
            valid_or_err(id, sim, full, evals)
        }
        Strategy::Network => {
            // Both networks are discrete-time (one step per sample): the step size only has
            // to be valid.
            // Budget that keeps the Hammerstein–Wiener fit (32 free weights, one network run
            // per weight per Jacobian) to a few seconds on the Dyke files; NARX has its own
            // ([`narx_net::Effort`]).
            let (iterations, window) = (3 * opts.lm_iterations.max(1), opts.swarm_window.min(6000));
            let mut evals = 0;
            // Hammerstein–Wiener's training depends on its random start (seed 1 and 2 can end
            // far apart); NARX's own effort schedule is kept to one start for its cost.
            let starts = if sp.structure == Structure::HammersteinWiener { restarts::MAX_STARTS } else { 1 };
            let t = restarts::until_agree(&format!("the {id} training"), opts.swarm.seed, starts, notes, |seed| {
                let t = narx::train(sp.structure, kin, y, rows, 1e-3, sp.rate, iterations, window, seed)?;
                evals += t.evaluations;
                let cost = full.cost(&t.params);
                Some((t.params, cost))
            })
            .ok_or_else(|| FitError::NoValidSet { model: id.to_owned() })?;
            valid_or_err(id, sim, t, evals)
        }
        Strategy::Global => global::global_fit(id, sp, sim, (kin, y, rows), y_scale, opts, notes, &full),
    }
}

fn valid_or_err(
    id: &str,
    sim: &dyn simulate::Simulator,
    p: Vec<f64>,
    evals: usize,
) -> Result<(Vec<f64>, usize), FitError> {
    if sim.valid(p.get(..sim.n_params()).unwrap_or(&p)) {
        Ok((p, evals))
    } else {
        Err(FitError::NoValidSet { model: id.to_owned() })
    }
}

#[cfg(test)]
mod tests;
