//! `hil-sim diagnose`: where a model and a recording disagree, which physics the model
//! leaves out (shared/spec/physics-catalog.md), and how much adding it helps on data the
//! refit did not see.
//!
//! 1. **Base.** The base model is fitted on the training part (the first
//!    `1 − heldout_fraction`) with the channels as recorded (`--delay off`: a time shift
//!    between channels is a finding, not something to absorb silently). `auto` fits every
//!    seed model ([`AUTO_BASES`]) and keeps the best held-out one.
//! 2. **Locate.** The base residual's energy over time (windows), over the operating space
//!    (input level, |rate|, direction, auxiliary channels) and over frequency
//!    ([`locate`]); its sample-to-sample noise floor.
//! 3. **Name.** Every candidate of the catalog the recording can show ([`candidates`]) is
//!    fitted to the residual: its nonlinear value (a time constant, a delay, a saturation
//!    level, an offset, a channel lag) scanned on a grid with the base model's Jacobian
//!    standing in for its refit, then the term refitted jointly with the base parameters
//!    ([`augment`]). Candidates are ranked by the Bayesian information criterion on the
//!    training part.
//! 4. **Model.** In that order, the first candidate whose held-out gain passes the paired
//!    block test ([`significance`]) is kept, and the search repeats on what remains (at
//!    most `max_findings` rounds). A recording with nothing missing ends with no finding.
//! 5. **Report.** Each finding says which physics, how big (its fitted values with units
//!    and the RMS of what it adds), where (windows and conditions where the gain
//!    concentrates) and the held-out error before and after ([`report`] draws the plots).

pub mod augment;
pub mod candidates;
pub mod locate;
pub mod report;
pub mod significance;

use std::collections::BTreeMap;
use std::time::Instant;

use indicatif::ProgressBar;
use rayon::prelude::*;
use serde::Serialize;
use thiserror::Error;

use crate::dispatch::RateChoice;
use crate::fit::{fit, Dataset, DelayChoice, FitError, FitOptions, FitResult};
use crate::metrics::{metrics, Metrics};
use augment::{Fitted, Problem, Term, Transform, Tune};
use candidates::{AuxChannel, Candidate, Role};
use locate::{Band, Condition};
use significance::Test;

/// The seed models `--model auto` chooses among: every parametric model of the papers
/// (the operator and data-driven models describe a loop without naming physics).
pub const AUTO_BASES: &[&str] =
    &["algebraic", "bouc_wen", "lugre", "tanh", "dahl", "spencer", "bingham", "arctan", "arctan_inertia", "trig"];

/// Levenberg–Marquardt iterations that converge the fitted base before the first round.
const BASE_ITERATIONS: usize = 8;
/// Levenberg–Marquardt iterations of every candidate's refit (from each start)…
const SCREEN_ITERATIONS: usize = 3;
/// …and the further ones for the [`POLISHED`] leading candidates; the reference a gain is
/// judged against gets both.
const POLISH_ITERATIONS: usize = 6;
const POLISHED: usize = 3;
/// Grid points of an input transform's profiled scan on each side of the identity, and the
/// iterations of each refit.
const PROFILE_POINTS: usize = 8;
const PROFILE_ITERATIONS: usize = 3;
/// Grid values between two starts for them to count as different basins.
const PROFILE_GAP: usize = 2;
/// Samples (from the start) whose training rows rank an input transform's grid values.
const PROFILE_SAMPLES: usize = 12_000;

/// Why a diagnosis could not run.
#[derive(Debug, Error)]
pub enum DiagnoseError {
    #[error(transparent)]
    Fit(#[from] FitError),
    #[error("--heldout {0}: must be between 0.05 and 0.8")]
    Heldout(f64),
    #[error("no base model could be fitted: {0}")]
    NoBase(String),
    #[error("the base model `{0}` cannot be refitted by the diagnosis (not a parametric model)")]
    NotParametric(String),
    #[error("the fitted base model `{0}` diverges when replayed")]
    Diverges(String),
}

/// How to diagnose.
#[derive(Clone, Debug)]
pub struct DiagnoseOptions {
    /// Base model id; `None` for `auto`.
    pub model: Option<String>,
    /// Fraction of the recording held out (the end of it).
    pub heldout: f64,
    /// Rate estimator of the models; `None`: the zero-phase offline rate
    /// ([`crate::rate_offline`]), so that no estimator lag is mistaken for the clutch's.
    pub rate: Option<RateChoice>,
    pub seed: u64,
    /// Rounds of naming and modelling.
    pub max_findings: usize,
}

impl Default for DiagnoseOptions {
    fn default() -> Self {
        Self { model: None, heldout: 0.3, rate: None, seed: 1, max_findings: 3 }
    }
}

/// One piece of missing physics, in the contract's shape.
#[derive(Clone, Debug, Serialize)]
pub struct Finding {
    pub effect: String,
    pub summary: String,
    /// Where the gain concentrates, seconds.
    pub windows: Vec<(f64, f64)>,
    /// Fitted values of the term (units in the names or in `units`).
    pub params: BTreeMap<String, f64>,
    /// Units of `params` entries whose name does not carry one.
    pub units: BTreeMap<String, String>,
    pub heldout_before: Metrics,
    pub heldout_after: Metrics,
    /// Operating conditions where the gain concentrates, strongest first.
    #[serde(rename = "where")]
    pub conditions: Vec<Condition>,
    /// The candidate as tested (label, channel, test outcome, size).
    pub evidence: Evidence,
}

/// How a candidate fared.
#[derive(Clone, Debug, Serialize)]
pub struct Evidence {
    pub label: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub channel: Option<String>,
    pub test: Test,
    /// RMS of what the term changes in the prediction, output units, and as a share of the
    /// output's span.
    pub term_rms: f64,
    pub term_share_of_span: f64,
    /// Training-part information criterion gain (positive: better).
    pub bic_gain: f64,
}

/// A candidate tested in one round.
#[derive(Clone, Debug, Serialize)]
pub struct Tested {
    pub round: usize,
    pub effect: String,
    pub label: String,
    /// The candidate's grid value (`tau_s`, `delay_s`, …) where it has one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub value: Option<(String, f64)>,
    pub bic_gain: f64,
    pub heldout_r_rmse_before: f64,
    pub heldout_r_rmse_after: f64,
    pub test: Test,
    pub kept: bool,
}

/// Where the base model's residual concentrates before anything is named.
#[derive(Clone, Debug, Serialize)]
pub struct Locate {
    /// RMS of the base residual over the held-out part, output units.
    pub residual_rms: f64,
    /// Sample-to-sample noise floor of the residual (white-noise estimate), output units.
    pub noise_rms: f64,
    pub windows: Vec<(f64, f64)>,
    pub conditions: Vec<Condition>,
    pub bands: Vec<Band>,
}

/// The whole diagnosis.
#[derive(Clone, Debug, Serialize)]
pub struct Diagnosis {
    pub base_model: String,
    pub heldout_fraction: f64,
    pub findings: Vec<Finding>,
    /// The base model as fitted, held-out part.
    pub base_heldout: Metrics,
    /// The model with every finding's term, held-out part.
    pub final_heldout: Metrics,
    /// Base models tried by `auto`, with their held-out R-RMSE.
    pub bases_tried: Vec<(String, f64)>,
    pub locate: Locate,
    pub channels: Vec<AuxChannel>,
    pub candidates: Vec<Tested>,
    pub seconds: f64,
    #[serde(skip)]
    pub plot: PlotData,
}

/// What the report draws.
#[derive(Clone, Debug, Default)]
pub struct PlotData {
    pub time: Vec<f64>,
    pub input: Vec<f64>,
    pub output: Vec<f64>,
    /// The base model as fitted and the final model.
    pub before: Vec<f64>,
    pub after: Vec<f64>,
    pub train_end: usize,
    pub heldout_rows: Vec<usize>,
    pub fs: f64,
}

/// Units of well-known channel names (the clutch contract's and the Dyke files').
pub fn unit_of(name: &str) -> Option<&'static str> {
    Some(match name {
        "b" | "B" => "T",
        "torque" | "T" | "torque_true" => "N·m",
        "F" => "N",
        "D" => "cm",
        "V" => "cm/s",
        "Y" => "V",
        "i" | "i_ref" => "A",
        "speed" => "rad/s",
        "temperature" => "°C",
        _ => return None,
    })
}

/// Diagnose `data` (its auxiliary channels `aux`: name and values; the command channel, if
/// the model uses one, is named by `command`). `pb` shows progress.
pub fn diagnose(
    data: &Dataset,
    aux: Vec<(String, Vec<f64>)>,
    command: Option<&str>,
    names: (&str, &str),
    opts: &DiagnoseOptions,
    pb: &ProgressBar,
) -> Result<Diagnosis, DiagnoseError> {
    let started = Instant::now();
    // Without a chosen estimator the models get the zero-phase rate: a causal estimator's
    // lag would otherwise be diagnosed as the clutch's.
    let mut data = data.clone();
    if opts.rate.is_none() {
        data.rates = Some(crate::rate_offline::rates(&data.input, data.dt));
    }
    let data = &data;
    let bases: Vec<&str> = match &opts.model {
        Some(m) => vec![m.as_str()],
        None => AUTO_BASES.to_vec(),
    };
    pb.set_length((bases.len() + 2 + 2 * opts.max_findings) as u64);
    // 1. Base.
    let fit_opts = FitOptions {
        rate: opts.rate,
        delay: DelayChoice::Off,
        swarm: crate::fit::global::SwarmOptions { seed: opts.seed, ..Default::default() },
        lm_iterations: 30,
        ..Default::default()
    };
    let mut fits: Vec<FitResult> = Vec::new();
    let mut errors = Vec::new();
    for id in &bases {
        pb.set_message(format!("fitting {id}"));
        match fit(id, data, &fit_opts) {
            Ok(r) => fits.push(r),
            Err(e) if opts.model.is_some() => return Err(e.into()),
            Err(e) => errors.push(format!("{id}: {e}")),
        }
        pb.inc(1);
    }
    let score = |r: &FitResult| r.heldout_unflagged.unwrap_or(r.heldout).rmse;
    let bases_tried: Vec<(String, f64)> =
        fits.iter().map(|r| (r.model.clone(), r.heldout_unflagged.unwrap_or(r.heldout).r_rmse)).collect();
    let base = fits
        .into_iter()
        .filter(|r| score(r).is_finite())
        .min_by(|a, b| score(a).total_cmp(&score(b)))
        .ok_or_else(|| DiagnoseError::NoBase(errors.join("; ")))?;
    let id = base.model.clone();
    let dt = data.dt;
    let sim =
        crate::fit::simulate::simulator(&id, dt as f32).ok_or_else(|| DiagnoseError::NotParametric(id.clone()))?;
    let spec = crate::fit::spec::spec(&id, &data.scales(), Some(base.rate_choice))
        .ok_or_else(|| DiagnoseError::NotParametric(id.clone()))?;
    if !matches!(
        spec.strategy,
        crate::fit::spec::Strategy::Linear | crate::fit::spec::Strategy::Local | crate::fit::spec::Strategy::Global
    ) {
        return Err(DiagnoseError::NotParametric(id));
    }
    // Rows away from the ends (delays and filters read past them).
    let n = data.len();
    let margin = (0.02 / dt).ceil() as usize + 2;
    let inside = |i: &usize| *i >= margin && *i + margin < n;
    let train: Vec<usize> = data.train_rows().into_iter().filter(inside).collect();
    let held: Vec<usize> = data.heldout_unflagged().into_iter().filter(inside).collect();
    let prob = Problem { data, sim: sim.as_ref(), spec: &spec, rate: base.rate_choice, train };
    let y = &data.output;
    let held_metrics = |pred: &[f64]| {
        let pick = |v: &[f64]| -> Vec<f64> { held.iter().map(|&i| v[i]).collect() };
        metrics(&pick(y), &pick(pred), None)
    };
    let base_heldout = held_metrics(&base.output);

    // 2. Locate.
    pb.set_message("locating");
    let channels = candidates::classify(data, aux, command);
    let (dx, _) = candidates::rates(data);
    let residual: Vec<f64> = y.iter().zip(&base.output).map(|(y, m)| y - m).collect();
    let all_rows: Vec<usize> = prob.train.iter().chain(&held).copied().collect();
    let mut energy: Vec<f64> = residual.iter().map(|r| r * r).collect();
    mask(&mut energy, &all_rows);
    let aux_refs: Vec<(&str, &[f64])> =
        channels.iter().filter(|c| c.role != Role::Unused).map(|c| (c.name.as_str(), c.values.as_slice())).collect();
    let noise_rms = {
        let d2: Vec<f64> =
            (1..n.saturating_sub(1)).map(|i| residual[i] - 0.5 * (residual[i - 1] + residual[i + 1])).collect();
        (d2.iter().map(|v| v * v).sum::<f64>() / d2.len().max(1) as f64 / 1.5).sqrt()
    };
    let fs = 1.0 / dt;
    let edges = locate::band_edges(fs);
    let held_residual: Vec<f64> = (data.train_end..n).map(|i| residual[i]).collect();
    let locate = Locate {
        residual_rms: base_heldout.rmse,
        noise_rms,
        windows: locate::windows(&data.time, &energy, dt, 2.0, 5),
        conditions: locate::conditions(&data.input, &dx, &aux_refs, &energy, &all_rows).into_iter().take(5).collect(),
        bands: locate::spectrum(&held_residual, fs, &edges),
    };
    pb.inc(1);

    // 3–4. Name and model, round by round.
    let cands = candidates::all(data, &channels);
    // The base as the refits see it: Gauss–Newton run on from the fit until it stalls, so
    // that a term is never credited with what more iterations of the base would have done.
    let mut current = prob
        .refit(&[], &[], None, &base.flat, BASE_ITERATIONS)
        .map(|r| r.0)
        .ok_or_else(|| DiagnoseError::Diverges(id.clone()))?;
    let mut findings = Vec::new();
    let mut tested = Vec::new();
    let mut used: Vec<usize> = Vec::new();
    let y_span = {
        let (lo, hi) = held.iter().fold((f64::MAX, f64::MIN), |(l, h), &i| (l.min(y[i]), h.max(y[i])));
        (hi - lo).max(1e-300)
    };
    for round in 0..opts.max_findings {
        pb.set_message(format!("round {}: naming", round + 1));
        let reference = prob
            .refit(&current.transforms, &current.terms, None, &current.theta, SCREEN_ITERATIONS + POLISH_ITERATIONS)
            .map(|r| r.0)
            .ok_or_else(|| DiagnoseError::Diverges(id.clone()))?;
        let Some(jac) = prob.jacobian_at(&reference.theta, &reference.transforms) else { break };
        let ntr = prob.train.len() as f64;
        let bic = |f: &Fitted| ntr * f.train_mse.max(1e-300).ln() + (f.extra_params() as f64) * ntr.ln();
        let bic_ref = bic(&reference);
        let mut scored: Vec<(usize, Fitted, f64, f64)> = cands
            .par_iter()
            .enumerate()
            .filter(|(k, _)| !used.contains(k))
            .filter_map(|(k, c)| {
                let (f, g) = refit_candidate(
                    &prob,
                    c,
                    &reference,
                    &starts_on_grid(&prob, c, &reference, &jac),
                    SCREEN_ITERATIONS,
                )?;
                let gain = bic_ref - bic(&f);
                Some((k, f, gain, g))
            })
            .collect();
        scored.sort_by(|a, b| b.2.total_cmp(&a.2));
        // The leading candidates get the rest of the refit's iterations.
        let polished: Vec<(usize, Fitted, f64, f64)> = scored
            .par_iter()
            .take(POLISHED)
            .filter_map(|(k, f, _, g)| {
                let c = &cands[*k];
                let base = Fitted { terms: f.terms[..reference.terms.len()].to_vec(), ..reference.clone() };
                let base = Fitted { theta: f.theta.clone(), ..base };
                let (f2, g2) = refit_candidate(&prob, c, &base, &[(*g, None)], POLISH_ITERATIONS)?;
                let better = if f2.train_mse < f.train_mse { (f2, g2) } else { (f.clone(), *g) };
                Some((*k, better.0.clone(), bic_ref - bic(&better.0), better.1))
            })
            .collect();
        for p in polished {
            if let Some(slot) = scored.iter_mut().find(|s| s.0 == p.0) {
                *slot = p;
            }
        }
        scored.sort_by(|a, b| b.2.total_cmp(&a.2));
        pb.inc(1);
        pb.set_message(format!("round {}: testing", round + 1));
        let before = held_metrics(&reference.pred);
        let mut accepted = None;
        for (k, f, gain, g) in scored {
            let c = &cands[k];
            let test = significance::test(y, &reference.pred, &f.pred, &held);
            let after = held_metrics(&f.pred);
            // What the term changes in the prediction must be resolvable above the noise.
            let change = (all_rows.iter().map(|&i| (f.pred[i] - reference.pred[i]).powi(2)).sum::<f64>()
                / all_rows.len().max(1) as f64)
                .sqrt();
            let resolvable = change >= significance::MIN_TERM_OF_NOISE * noise_rms;
            let kept =
                accepted.is_none() && gain > 0.0 && f.train_mse < reference.train_mse && test.significant && resolvable;
            tested.push(Tested {
                round: round + 1,
                effect: c.effect.to_owned(),
                label: c.label.clone(),
                value: c.grid_name.clone().map(|n| (n, g)),
                bic_gain: gain,
                heldout_r_rmse_before: before.r_rmse,
                heldout_r_rmse_after: after.r_rmse,
                test,
                kept,
            });
            if kept {
                accepted = Some((k, f, gain, g, test, after));
            }
        }
        pb.inc(1);
        let Some((k, f, gain, g, test, after)) = accepted else { break };
        let c = &cands[k];
        let finding = describe(
            data,
            &prob,
            c,
            &f,
            &reference,
            g,
            names,
            (before, after),
            test,
            gain,
            y_span,
            &dx,
            &aux_refs,
            &all_rows,
        );
        findings.push(finding);
        used.push(k);
        // A candidate of the same effect on the same channel is not tested again.
        for (j, o) in cands.iter().enumerate() {
            if o.effect == c.effect && o.channel == c.channel {
                used.push(j);
            }
        }
        current = f;
    }
    let final_heldout = held_metrics(&current.pred);
    pb.finish_and_clear();
    Ok(Diagnosis {
        base_model: id,
        heldout_fraction: opts.heldout,
        findings,
        base_heldout,
        final_heldout: if current.transforms.is_empty() && current.terms.is_empty() {
            base_heldout
        } else {
            final_heldout
        },
        bases_tried,
        locate,
        channels,
        candidates: tested,
        seconds: started.elapsed().as_secs_f64(),
        plot: PlotData {
            time: data.time.clone(),
            input: data.input.clone(),
            output: y.clone(),
            before: base.output.clone(),
            after: current.pred.clone(),
            train_end: data.train_end,
            heldout_rows: held,
            fs,
        },
    })
}

/// Refit candidate `c` on top of `current` from each of `starts` (its value); the best by
/// training error, with its value.
fn refit_candidate(
    prob: &Problem<'_>,
    c: &Candidate,
    current: &Fitted,
    starts: &[Start],
    iterations: usize,
) -> Option<(Fitted, f64)> {
    let build = |g: f64| {
        let p = (c.build)(g);
        (p.transform, p.terms)
    };
    let lo = c.grid.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = c.grid.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    starts
        .iter()
        .filter_map(|(g, theta)| {
            let g = *g;
            let theta = theta.as_deref().unwrap_or(&current.theta);
            if c.grid.len() > 1 {
                let tune = Tune { build: &build, start: g, lo, hi, log: lo > 0.0 };
                prob.refit(&current.transforms, &current.terms, Some(&tune), theta, iterations)
            } else {
                let (transforms, terms) = with_candidate(current, c, g);
                prob.refit(&transforms, &terms, None, theta, iterations).map(|r| (r.0, g))
            }
        })
        .min_by(|a, b| a.0.train_mse.total_cmp(&b.0.train_mse))
}

/// The transforms and terms of `current` with candidate `c`'s piece at value `g` added.
fn with_candidate(current: &Fitted, c: &Candidate, g: f64) -> (Vec<Transform>, Vec<Term>) {
    let piece = (c.build)(g);
    let mut transforms = current.transforms.clone();
    transforms.extend(piece.transform);
    let mut terms = current.terms.clone();
    terms.extend(piece.terms);
    (transforms, terms)
}

/// A starting value of a candidate's refit, with the base parameters θ to start from
/// (`None`: the current model's).
type Start = (f64, Option<Vec<f64>>);

/// Zero the energy outside `rows`.
fn mask(e: &mut [f64], rows: &[usize]) {
    let mut keep = vec![false; e.len()];
    for &i in rows {
        if let Some(k) = keep.get_mut(i) {
            *k = true;
        }
    }
    for (v, k) in e.iter_mut().zip(keep) {
        if !k {
            *v = 0.0;
        }
    }
}

/// Starting values for the candidate's refit: its grid value with the lowest linearised
/// training cost (refined by a parabola through its neighbours on the grid) and, when the
/// cost has another local minimum on the grid, the best of those (a base model can absorb
/// part of an effect, which shifts the linearised minimum; the refit decides).
fn starts_on_grid(prob: &Problem<'_>, c: &Candidate, current: &Fitted, jac: &[Vec<f64>]) -> Vec<Start> {
    let cost_at = |g: f64| -> Option<f64> {
        let (transforms, terms) = with_candidate(current, c, g);
        prob.scan_cost(&transforms, &terms, &current.theta, jac)
    };
    if c.grid.len() < 2 {
        return c.grid.iter().map(|&g| (g, None)).collect();
    }
    // A transform of the input moves the base model's optimum far (its rate term absorbs
    // part of a delay or a lag): the linearisation cannot follow, so the cost at a subset of
    // the grid comes from a short refit of θ instead, walked outward from the identity so
    // that each refit starts from its neighbour's θ (a continuation: a refit from the
    // untransformed θ does not converge for a large delay, and its cost would rank a small
    // one first).
    if c.grid.first().is_some_and(|&g| (c.build)(g).transform.is_some()) {
        // The first PROFILE_SAMPLES of the training part rank the grid values.
        let short = Problem {
            data: prob.data,
            sim: prob.sim,
            spec: prob.spec,
            rate: prob.rate,
            train: prob.train.iter().copied().take_while(|&i| i < PROFILE_SAMPLES).collect(),
        };
        let prob = if short.train.len() >= 1000 { &short } else { prob };
        let profile: Vec<(f64, f64, Option<Vec<f64>>)> = continuation_chains(c, &prob.data.input, prob.data.dt)
            .par_iter()
            .flat_map_iter(|chain| {
                let mut theta = current.theta.clone();
                let mut out = Vec::with_capacity(chain.len());
                for &g in chain {
                    let (transforms, terms) = with_candidate(current, c, g);
                    match prob.refit(&transforms, &terms, None, &theta, PROFILE_ITERATIONS) {
                        Some((f, _)) => {
                            out.push((g, f.train_mse, Some(f.theta.clone())));
                            theta = f.theta;
                        }
                        None => out.push((g, f64::INFINITY, None)),
                    }
                }
                out
            })
            .collect();
        let mut order: Vec<usize> = (0..profile.len()).filter(|&k| profile[k].1.is_finite()).collect();
        order.sort_by(|&a, &b| profile[a].1.total_cmp(&profile[b].1));
        // The best value, and the best one that is not next to it on the grid (another basin).
        let gap = |a: f64, b: f64| c.grid.iter().filter(|&&g| (g - a) * (g - b) < 0.0).count() > PROFILE_GAP;
        // Each start carries the θ its profile refit reached.
        let mut out: Vec<Start> = Vec::new();
        if let Some(&a) = order.first() {
            out.push((profile[a].0, profile[a].2.clone()));
            if let Some(&b) = order.iter().find(|&&j| gap(profile[a].0, profile[j].0)) {
                out.push((profile[b].0, profile[b].2.clone()));
            }
        }
        return out;
    }
    let costs: Vec<f64> = c.grid.iter().map(|&g| cost_at(g).unwrap_or(f64::INFINITY)).collect();
    let finite = |k: &usize| costs[*k].is_finite();
    let Some(k) = (0..costs.len()).filter(finite).min_by(|&a, &b| costs[a].total_cmp(&costs[b])) else {
        return Vec::new();
    };
    let mut best = (c.grid[k], costs[k]);
    if k > 0 && k + 1 < costs.len() {
        let (l, m, r) = (costs[k - 1], costs[k], costs[k + 1]);
        let curv = l - 2.0 * m + r;
        if curv > 0.0 && curv.is_finite() {
            let off = (0.5 * (l - r) / curv).clamp(-0.5, 0.5);
            let g = if off >= 0.0 {
                c.grid[k] + off * (c.grid[k + 1] - c.grid[k])
            } else {
                c.grid[k] - off * (c.grid[k - 1] - c.grid[k])
            };
            if let Some(cost) = cost_at(g).filter(|v| *v < best.1) {
                best = (g, cost);
            }
        }
    }
    let mut out = vec![(best.0, None)];
    let local_min = |j: usize| {
        let l = if j > 0 { costs[j - 1] } else { f64::INFINITY };
        let r = costs.get(j + 1).copied().unwrap_or(f64::INFINITY);
        costs[j] <= l && costs[j] <= r
    };
    if let Some(j) = (0..costs.len())
        .filter(finite)
        .filter(|&j| j.abs_diff(k) > 1 && local_min(j))
        .min_by(|&a, &b| costs[a].total_cmp(&costs[b]))
    {
        out.push((c.grid[j], None));
    }
    out
}

/// The grid of an input-transform candidate as chains walked outward from the identity:
/// values split by sign (a delay or an offset either way; a lag or a saturation level has
/// one sign) and each side ordered by how far the transform moves the input, thinned to
/// [`PROFILE_POINTS`].
fn continuation_chains(c: &Candidate, x: &[f64], dt: f64) -> Vec<Vec<f64>> {
    let distance = |g: f64| -> f64 {
        let Some(t) = (c.build)(g).transform else { return f64::INFINITY };
        let y = t.apply(x, dt);
        x.iter().zip(&y).map(|(a, b)| (a - b) * (a - b)).sum::<f64>()
    };
    [false, true]
        .iter()
        .filter_map(|&negative| {
            let mut side: Vec<(f64, f64)> =
                c.grid.iter().filter(|&&g| (g < 0.0) == negative).map(|&g| (distance(g), g)).collect();
            side.sort_by(|a, b| a.0.total_cmp(&b.0));
            let step = side.len().div_ceil(PROFILE_POINTS).max(1);
            let chain: Vec<f64> = side.iter().step_by(step).map(|p| p.1).collect();
            (!chain.is_empty()).then_some(chain)
        })
        .collect()
}

/// A finding's text, values, windows and conditions.
#[allow(clippy::too_many_arguments)]
fn describe(
    data: &Dataset,
    prob: &Problem<'_>,
    c: &Candidate,
    f: &Fitted,
    reference: &Fitted,
    g: f64,
    names: (&str, &str),
    (before, after): (Metrics, Metrics),
    test: Test,
    bic_gain: f64,
    y_span: f64,
    dx: &[f64],
    aux: &[(&str, &[f64])],
    rows: &[usize],
) -> Finding {
    let y = &data.output;
    let (xu, yu) = (unit_of(names.0).unwrap_or(""), unit_of(names.1).unwrap_or(""));
    let change: Vec<f64> = f.pred.iter().zip(&reference.pred).map(|(a, b)| a - b).collect();
    let term_rms = (rows.iter().map(|&i| change[i] * change[i]).sum::<f64>() / rows.len().max(1) as f64).sqrt();
    let share = term_rms / y_span;
    let mut gain_e: Vec<f64> =
        (0..y.len()).map(|i| (y[i] - reference.pred[i]).powi(2) - (y[i] - f.pred[i]).powi(2)).collect();
    mask(&mut gain_e, rows);
    let gain_pos: Vec<f64> = gain_e.iter().map(|v| v.max(0.0)).collect();
    let windows = locate::windows(&data.time, &gain_pos, data.dt, 2.0, 5);
    let conditions: Vec<Condition> =
        locate::conditions(&data.input, dx, aux, &gain_pos, rows).into_iter().take(3).collect();
    let mut params = BTreeMap::new();
    let mut units = BTreeMap::new();
    if let Some(name) = &c.grid_name {
        params.insert(name.clone(), g);
        if name == "b_sat" || name == "b_0" {
            units.insert(name.clone(), xu.to_owned());
        }
    }
    let n_old = reference.terms.len();
    for (t, b) in f.terms.iter().zip(&f.beta).skip(n_old) {
        params.insert(t.name.clone(), *b);
    }
    params.insert("term_rms".into(), term_rms);
    units.insert("term_rms".into(), yu.to_owned());
    let _ = prob;
    let ch = c.channel.clone().unwrap_or_default();
    let size =
        format!("it changes the {} by {} RMS ({:.1} % of its span)", names.1, with_unit(term_rms, yu), 100.0 * share);
    let what = match c.effect {
        "field_lag" => format!(
            "the {o} lags the {i} reading by a first-order lag of {:.2} ms (eddy currents, the fluid's chain-forming time, coil dynamics)",
            1e3 * g,
            o = names.1,
            i = names.0
        ),
        "transport_delay" if g >= 0.0 => format!(
            "the {o} responds to the {i} channel {:.2} ms late ({:.1} samples): a timing skew between the channels (ADC pipeline, logger, a filter on one channel)",
            1e3 * g,
            g / data.dt,
            o = names.1,
            i = names.0
        ),
        "transport_delay" => format!(
            "the {i} channel is recorded {:.2} ms late relative to the {o} ({:.1} samples): a timing skew between the channels (ADC pipeline, logger, a filter on one channel)",
            -1e3 * g,
            -g / data.dt,
            o = names.1,
            i = names.0
        ),
        "saturation" => format!(
            "the {i} saturates: the {o} follows b_s·tanh(b/b_s) with b_s = {} (yield stress or steel saturating at high field)",
            with_unit(g, xu),
            o = names.1,
            i = names.0
        ),
        "sensor_offset" => format!(
            "the {i} reading carries a zero offset of {} (Hall offset or remanent field)",
            with_unit(g, xu),
            i = names.0
        ),
        "rate_dependence" => format!(
            "the loop changes with the excitation rate beyond the model's linear rate term (a |rate|·rate term, coefficient {:.3e})",
            f.beta.get(n_old).copied().unwrap_or(0.0)
        ),
        "asymmetry" => format!(
            "loading and unloading differ by an amount growing with the {i} (δ = {:.3e} {yu} per {xu})",
            f.beta.get(n_old).copied().unwrap_or(0.0),
            i = names.0
        ),
        "thermal_drift" if !ch.is_empty() => format!(
            "the {o} drifts with the temperature channel {ch} (scale {:+.3e} per unit, the fluid's viscosity and yield stress falling as it heats)",
            f.beta.get(n_old).copied().unwrap_or(0.0),
            o = names.1
        ),
        "thermal_drift" => format!(
            "the {o} drifts with the energy dissipated so far (the fluid heating up: scale {:+.3} over the recording)",
            f.beta.get(n_old).copied().unwrap_or(0.0),
            o = names.1
        ),
        "slip_speed" => format!(
            "the {o} depends on the slip speed {ch} (viscous shear the field-only model ignores)",
            o = names.1
        ),
        "inertia" if !ch.is_empty() => format!(
            "an inertial term in the {o} follows the acceleration from {ch} (coefficient {:.3e})",
            f.beta.get(n_old).copied().unwrap_or(0.0),
            o = names.1
        ),
        "inertia" => format!(
            "an inertial term m·ẍ in the {o} (m = {:.3e} {yu} per {xu}/s²; fluid or piston mass)",
            f.beta.get(n_old).copied().unwrap_or(0.0),
            o = names.1
        ),
        "aux_dependence" => format!(
            "the {o} depends on the channel {ch}: the model's parameters scale with it (α = {:+.3e} per unit of {ch}), and the dependence lags {ch} by a first-order lag of {:.1} ms",
            f.beta.get(n_old).copied().unwrap_or(0.0),
            1e3 * g,
            o = names.1
        ),
        other => other.to_owned(),
    };
    let summary = format!(
        "{what}; {size}; held-out R-RMSE {:.2} % -> {:.2} % ({:.0} % lower)",
        100.0 * before.r_rmse,
        100.0 * after.r_rmse,
        100.0 * test.gain
    );
    Finding {
        effect: c.effect.to_owned(),
        summary,
        windows,
        params,
        units,
        heldout_before: before,
        heldout_after: after,
        conditions,
        evidence: Evidence {
            label: c.label.clone(),
            channel: c.channel.clone(),
            test,
            term_rms,
            term_share_of_span: share,
            bic_gain,
        },
    }
}

fn with_unit(v: f64, unit: &str) -> String {
    let s = if v != 0.0 && (v.abs() >= 1e4 || v.abs() < 1e-2) { format!("{v:.3e}") } else { format!("{v:.3}") };
    if unit.is_empty() {
        s
    } else {
        format!("{s} {unit}")
    }
}

/// Keep `Transform` in the public surface for the report.
pub type InputTransform = Transform;

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// A bouc_wen recording of a two-tone input; the model is fed the input through
    /// `effect` and the output gets white noise of 0.5 % of its span.
    fn recording(effect: Option<Transform>, seed: u64) -> Dataset {
        let dt = 1e-3;
        let n = 12_000;
        let time: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let x: Vec<f64> = time
            .iter()
            .map(|t| {
                (2.0 * std::f64::consts::PI * 2.0 * t).sin()
                    + 0.5 * (2.0 * std::f64::consts::PI * 7.3 * t + 1.0).sin()
                    + 0.25 * (2.0 * std::f64::consts::PI * 13.1 * t + 2.0).sin()
            })
            .collect();
        let seen = effect.map_or_else(|| x.clone(), |e| e.apply(&x, dt));
        // The clutch's physics sees the true rate (here the zero-phase one of the clean input).
        let rates = crate::rate_offline::rates(&seen, dt);
        let samples = crate::replay::samples_with_rates(&seen, None, Some(&rates));
        let truth = [3.0, 2.0, 1.0, 1.0, 2.0, 0.4, 0.8, 0.0];
        let out = crate::dispatch::replay("bouc_wen", &truth, dt as f32, RateChoice::Backward, &samples).unwrap();
        let y: Vec<f64> = out.y.iter().map(|v| f64::from(*v)).collect();
        let (lo, hi) = y.iter().fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
        let noise = 0.005 * (hi - lo);
        let output = y.iter().map(|v| v + noise * (rng.random::<f64>() - 0.5) * 12f64.sqrt()).collect();
        Dataset { dt, time, input: x, output, command: None, train_end: 8400, excluded: vec![false; n], rates: None }
    }

    fn run(data: &Dataset) -> Diagnosis {
        let opts = DiagnoseOptions { model: Some("bouc_wen".into()), ..Default::default() };
        diagnose(data, vec![], None, ("b", "torque"), &opts, &ProgressBar::hidden()).unwrap()
    }

    #[test]
    fn a_field_lag_is_named_with_its_time_constant() {
        let d = run(&recording(Some(Transform::Lag { tau_s: 0.004 }), 1));
        let top = d.findings.first().expect("a finding");
        assert_eq!(top.effect, "field_lag", "{:#?}", d.candidates);
        let tau = top.params["tau_s"];
        assert!((tau - 0.004).abs() < 0.0015, "tau {tau}");
        assert!(top.heldout_after.rmse < 0.8 * top.heldout_before.rmse);
    }

    #[test]
    fn nothing_missing_gives_no_finding() {
        let d = run(&recording(None, 2));
        assert!(d.findings.is_empty(), "{:#?}", d.findings);
        assert!(!d.candidates.is_empty(), "every candidate is still tested");
    }
}
