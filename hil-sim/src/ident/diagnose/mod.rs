//! `hil-sim diagnose`: where a model and a recording disagree, which physics the model
//! leaves out (shared/spec/physics-catalog.md), and how much adding it helps on data the
//! refit did not see.
//!
//! 1. **Base** ([`base`]). The base model is fitted on the training part (the first
//!    `1 − heldout_fraction`) with the channels as recorded (no delay fitted: a time shift
//!    between channels is a finding, not something to absorb silently). `auto` fits every
//!    seed model ([`AUTO_BASES`]); the structurally different ones close to the best, and the
//!    algebraic model with play operators, each get the first round, and the base whose first
//!    round predicts the held-out part best is kept ([`contenders`]). A static power-law term of
//!    the input ([`level_map`]: the torque growing faster than linearly with the field) joins
//!    the base when it helps, with a note: a curvature the base family lacks is not physics
//!    left out.
//! 2. **Locate** ([`locate`]). The base residual's energy over time (windows), over the
//!    operating space (input level, |rate|, direction, auxiliary channels) and over
//!    frequency; its sample-to-sample noise floor.
//! 3. **Name** ([`candidates`], [`scan`], [`profile`], [`refit`], [`rank`]). Every
//!    candidate of the catalog the recording can show is fitted to the residual: its
//!    nonlinear value (a time constant, a delay, a saturation level, an offset, a channel
//!    lag) scanned on a grid with the base model's Jacobian standing in for its refit (an
//!    input transform's grid profiled by short refits instead), then the term refitted
//!    jointly with the base parameters ([`augment`]); on a base affine in some of its
//!    parameters (tanh), an additive term's refit also starts where base and term fit best
//!    together on the base's grid ([`joint_grid`]). Candidates are ranked by the
//!    Bayesian information criterion on the training part.
//! 4. **Model** ([`accept`]). Of the candidates whose held-out gain passes the paired block
//!    test ([`significance`]), the one that predicts the held-out part best is kept; one the
//!    tail alone leaves undecided, or two effects the tail cannot tell apart, are refitted on
//!    the reversed split ([`replicate`]). The search repeats on what remains (at most
//!    `max_findings` rounds). A recording with nothing missing ends with no finding.
//! 5. **Report** ([`describe`], [`crate::report::diagnose`]). Each finding says which physics, how big (its
//!    fitted values with units and the RMS of what it adds), where (windows and conditions
//!    where the gain concentrates) and the held-out error before and after; [`crate::report::diagnose`]
//!    draws the plots.

pub mod accept;
pub mod acting;
pub mod augment;
pub mod base;
pub mod candidates;
pub mod contenders;
pub mod decimate;
pub mod describe;
pub mod diagnosis;
pub mod fed;
pub mod joint_grid;
pub mod lag_or_delay;
pub mod leak;
pub mod level_map;
pub mod locate;
pub mod options;
pub mod physical;
pub mod play;
pub mod profile;
pub mod projection;
pub mod rank;
pub mod refit;
pub mod replicate;
pub mod runs;
pub mod scan;
pub mod significance;
pub mod transform;
pub mod zero_phase;

use std::time::Instant;

use crate::ident::fit::Dataset;
use crate::progress::Progress;
use accept::Judge;
use candidates::Role;
use describe::Described;
use transform::Transform;

pub use base::AUTO_BASES;
pub use describe::unit_of;
pub use diagnosis::{Diagnosis, Evidence, Finding, PlotData, Tested};
pub use locate::Locate;
pub use options::{DiagnoseError, DiagnoseOptions};

/// Diagnose `data` (its auxiliary channels `aux`: name and values; the command channel, if
/// the model uses one, is named by `command`; `names` are the input's and the output's).
/// One progress stage: a step per base model fitted, one for locating, two per round.
///
/// A recording sampled faster than [`decimate::TARGET_HZ`] is diagnosed on block means at
/// about that rate ([`decimate`]), and a note says so.
pub fn diagnose(
    data: &Dataset,
    aux: Vec<(String, Vec<f64>)>,
    command: Option<&str>,
    names: (&str, &str),
    opts: &DiagnoseOptions,
    progress: &dyn Progress,
) -> Result<Diagnosis, DiagnoseError> {
    let q = decimate::factor(data.dt);
    if q < 2 {
        return diagnose_at_rate(data, aux, command, names, opts, progress);
    }
    let started = Instant::now();
    let d = decimate::decimate(data, aux, &opts.boundaries, q);
    let opts = DiagnoseOptions { boundaries: d.boundaries, ..opts.clone() };
    let mut out = diagnose_at_rate(&d.data, d.aux, command, names, &opts, progress)?;
    out.notes.push(format!(
        "the recording ({:.0} Hz) was diagnosed at {:.0} Hz, on the means of blocks of {q} samples (every effect of the \
         catalog lives far below that rate)",
        1.0 / data.dt,
        1.0 / d.data.dt
    ));
    out.seconds = started.elapsed().as_secs_f64();
    Ok(out)
}

/// [`diagnose`] at the recording's own rate.
fn diagnose_at_rate(
    data: &Dataset,
    aux: Vec<(String, Vec<f64>)>,
    command: Option<&str>,
    names: (&str, &str),
    opts: &DiagnoseOptions,
    progress: &dyn Progress,
) -> Result<Diagnosis, DiagnoseError> {
    let started = Instant::now();
    // Without a chosen estimator the models get the zero-phase rate: a causal estimator's
    // lag would otherwise be diagnosed as the clutch's.
    let (data, rate_cutoff_hz, rate_note) = with_zero_phase_rate(data, opts, names.0);
    let data = &data;
    let bases = base::choices(opts);
    progress.stage("diagnosing", (bases.len() + 2 + 2 * opts.max_findings) as u64);
    // 1. Base: every seed model fitted; the structurally different ones close to the best
    // get the first round each, and the one whose first round predicts best is kept.
    let fitted = base::fit_bases(data, &bases, opts, progress)?;
    let (train, held) = base::rows(data);
    let all_rows: Vec<usize> = train.iter().chain(&held).copied().collect();
    progress.message("locating");
    let channels = candidates::classify(data, aux, command);
    let (dx, _) = candidates::rates(data);
    let aux_refs: Vec<(&str, &[f64])> =
        channels.iter().filter(|c| c.role != Role::Unused).map(|c| (c.name.as_str(), c.values.as_slice())).collect();
    let cands = candidates::all(data, &channels, unit_of(names.0) == Some("T"), rate_cutoff_hz);
    let judge0 = Judge { y: &data.output, held: &held, rows: &all_rows, noise_rms: 0.0, dt: data.dt };
    progress.advance(1);
    progress.message("round 1: naming");
    let shared = contenders::Shared {
        data,
        train: &train,
        judge: &judge0,
        cands: &cands,
        rate: &dx,
        aux: &aux_refs,
        rate_cutoff_hz,
        feeds: Default::default(),
    };
    let mut openings = contenders::open_all(&fitted, &shared)?;
    let (chosen, settled, contenders) = contenders::settle(&mut openings, &judge0, names);
    let mut notes: Vec<String> = fitted.failed.iter().cloned().chain(rate_note).chain(settled).collect();
    let contenders::Opening { base, before, prob, mut current, located, first, .. } = openings.swap_remove(chosen);
    let id = base.fit.model.clone();
    let judge = Judge { noise_rms: located.noise_rms, ..judge0 };
    let base_heldout = judge.heldout(&before);
    let reference_heldout = first.as_ref().map_or_else(|| judge.heldout(&current.pred), |(_, v)| v.before);
    // 3–4. Name and model, round by round.
    let diverges = || DiagnoseError::Diverges(id.clone());
    let (mut findings, mut tested, mut used) = (Vec::new(), Vec::new(), Vec::<usize>::new());
    let y_span = span_on(&data.output, &held);
    // Joins of a dataset's runs, with any the caller gave: a finding sitting on one says so.
    let boundaries: Vec<usize> =
        opts.boundaries.iter().copied().chain(data.run_starts().into_iter().filter(|&s| s > 0)).collect();
    let mut first = Some(first);
    for round in 0..opts.max_findings {
        progress.message(&format!("round {}: naming", round + 1));
        let opened = match first.take() {
            Some(f) => f,
            None => {
                let reference = rank::reference(&prob, &current).ok_or_else(diverges)?;
                rank::rank(&prob, &cands, &reference, &used).map(|(reference, ranked)| {
                    let verdict = judge.round(round + 1, &prob, &cands, &reference, ranked, &findings);
                    (reference, verdict)
                })
            }
        };
        let Some((reference, verdict)) = opened else {
            notes.push(jacobian_note(round + 1, &id));
            break;
        };
        progress.advance(2);
        tested.extend(verdict.tested);
        let Some(kept) = verdict.accepted else { break };
        let effect = kept.reading.effect;
        let runner_up = describe::runner_up(&tested, round + 1, effect, &kept.test, kept.after.r_rmse);
        findings.push(describe::finding(&Described {
            data,
            candidate: &cands[kept.scored.index],
            reading: &kept.reading,
            fitted: &kept.scored.fitted,
            reference: &reference,
            value: kept.scored.value,
            names,
            before: verdict.before,
            after: kept.after,
            test: kept.test,
            replication: kept.replication,
            lag_or_delay: kept.lag_or_delay,
            acting: kept.acting,
            bic_gain: kept.scored.bic_gain,
            y_span,
            rate: &dx,
            aux: &aux_refs,
            rows: &all_rows,
            boundaries: &boundaries,
            runner_up,
        }));
        used.extend(spent(&cands, kept.scored.index, effect));
        current = kept.scored.fitted;
    }
    let final_heldout = if findings.is_empty() { reference_heldout } else { judge.heldout(&current.pred) };
    Ok(Diagnosis {
        base_model: id,
        heldout_fraction: opts.heldout,
        findings,
        base_heldout,
        reference_heldout,
        final_heldout,
        bases_tried: fitted.tried,
        contenders,
        locate: located,
        channels,
        candidates: tested,
        notes,
        units: (unit_of(names.0).unwrap_or("").to_owned(), unit_of(names.1).unwrap_or("").to_owned()),
        seconds: started.elapsed().as_secs_f64(),
        plot: plot_data(data, before, current.pred, held),
    })
}

/// What the report plots: the recording, the base's prediction `before` and the final one
/// `after`, the held-out rows.
fn plot_data(data: &Dataset, before: Vec<f64>, after: Vec<f64>, held: Vec<usize>) -> PlotData {
    PlotData {
        time: data.time.clone(),
        input: data.input.clone(),
        output: data.output.clone(),
        before,
        after,
        train_end: data.train_end,
        heldout_rows: held,
        fs: 1.0 / data.dt,
    }
}

/// `data` with the models' zero-phase rate at [`crate::numerics::derivative::content_cutoff`]
/// (unless `opts` chose an estimator), that cutoff (Hz), and the note saying so when it is
/// below fs/8 (`input`: the input channel's name).
fn with_zero_phase_rate(data: &Dataset, opts: &DiagnoseOptions, input: &str) -> (Dataset, f64, Option<String>) {
    use crate::numerics::derivative::{content_cutoff, rates_below, CUTOFF_OF_CONTENT, CUTOFF_OF_FS};
    let mut data = data.clone();
    let top = CUTOFF_OF_FS / data.dt;
    if opts.rate.is_some() {
        // The models use the chosen estimator: no given rates, so the cutoff is never read.
        return (data, top, None);
    }
    let cutoff = content_cutoff(&data.input, data.dt);
    data.rates = Some(rates_below(&data.input, data.dt, cutoff));
    let note = (cutoff < top).then(|| {
        format!(
            "the models' rate of {input} was smoothed (zero phase) at {cutoff:.0} Hz, not {top:.0} Hz: 99.9 % of \
             {input}'s power lies below {:.1} Hz, and the band above it only adds the reading's noise to the rate",
            cutoff / CUTOFF_OF_CONTENT
        )
    });
    (data, cutoff, note)
}

/// The kept candidate `k` (read as `effect`) and every candidate of that effect on its
/// channel: none of them is tested again.
fn spent<'a>(cands: &'a [candidates::Candidate], k: usize, effect: &'a str) -> impl Iterator<Item = usize> + 'a {
    let channel = cands.get(k).and_then(|c| c.channel.as_deref());
    (0..cands.len()).filter(move |&j| j == k || (cands[j].effect == effect && cands[j].channel.as_deref() == channel))
}

/// The note of a round (1-based) whose base `id` could not be differentiated.
fn jacobian_note(round: usize, id: &str) -> String {
    format!(
        "round {round}: the base model {id}'s Jacobian could not be taken at its fitted parameters (its replay \
         diverges when a parameter is nudged), so no further candidate was tested"
    )
}

/// Peak-to-peak of `y` over `rows`.
fn span_on(y: &[f64], rows: &[usize]) -> f64 {
    let (lo, hi) = rows.iter().fold((f64::MAX, f64::MIN), |(l, h), &i| (l.min(y[i]), h.max(y[i])));
    (hi - lo).max(1e-300)
}

/// Keep `Transform` in the public surface for the report.
pub type InputTransform = Transform;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::RateSpec;
    use augment::{Fitted, Problem};
    use candidates::Candidate;
    use rand::{Rng, SeedableRng};

    /// A bouc_wen recording of a three-tone input; the model is fed the input through
    /// `effect` and the output gets white noise of 0.5 % of its span.
    pub(super) fn recording(effect: Option<Transform>, seed: u64) -> Dataset {
        let tone = |t: f64, f: f64, ph: f64| (2.0 * std::f64::consts::PI * f * t + ph).sin();
        let x = |t: f64| tone(t, 2.0, 0.0) + 0.5 * tone(t, 7.3, 1.0) + 0.25 * tone(t, 13.1, 2.0);
        recording_with(x, effect, |_| 0.0, seed)
    }

    /// 12 s at 1 kHz of model-core's Bouc–Wen fed the input `x(t)` through `effect`, with
    /// `extra(x)` added to its output and white noise of 0.5 % of the output's span; the
    /// first 70 % trains.
    pub(super) fn recording_with(
        x: impl Fn(f64) -> f64,
        effect: Option<Transform>,
        extra: impl Fn(f64) -> f64,
        seed: u64,
    ) -> Dataset {
        let dt = 1e-3;
        let n = 12_000;
        let time: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let x: Vec<f64> = time.iter().map(|&t| x(t)).collect();
        let seen = effect.map_or_else(|| x.clone(), |e| e.apply(&x, dt));
        let y: Vec<f64> = bouc_wen_truth(&seen, dt).iter().zip(&x).map(|(v, x)| v + extra(*x)).collect();
        with_noise(x, &y, &mut rng)
    }

    /// The tests' true clutch, model-core's Bouc–Wen, fed `seen` (sampled every `dt` s) with
    /// its true rate (here the zero-phase one of the clean input).
    pub(super) fn bouc_wen_truth(seen: &[f64], dt: f64) -> Vec<f64> {
        let rates = crate::numerics::derivative::rates(seen, dt);
        let samples = crate::models::replay::samples_with_rates(seen, None, Some(&rates));
        let truth = [3.0, 2.0, 1.0, 1.0, 2.0, 0.4, 0.8, 0.0];
        let out = crate::models::replay("bouc_wen", &truth, dt as f32, RateSpec::Backward, &samples).unwrap();
        out.y.iter().map(|v| f64::from(*v)).collect()
    }

    /// The tests' Bouc–Wen clutch fed `x` (sampled every `dt` s) with `term` added, scaled so
    /// that its `size` is `share` of the clutch's torque span.
    pub(super) fn bouc_wen_plus(x: &[f64], dt: f64, term: &[f64], share: f64, size: fn(&[f64]) -> f64) -> Vec<f64> {
        let m = bouc_wen_truth(x, dt);
        let (lo, hi) = crate::numerics::stats::min_max(&m);
        let k = share * (hi - lo) / size(term);
        m.iter().zip(term).map(|(m, t)| m + k * t).collect()
    }

    /// `n` samples of uniform white noise from `rng` through four zero-phase first-order
    /// low-passes at `hz` (sampled every `dt` s), scaled to a peak of 1.
    fn band_limited(rng: &mut impl Rng, n: usize, dt: f64, hz: f64) -> Vec<f64> {
        let mut white: Vec<f64> = (0..n).map(|_| rng.random::<f64>() - 0.5).collect();
        for _ in 0..4 {
            white = crate::numerics::derivative::filtfilt(&white, 1.0 / (2.0 * std::f64::consts::PI * hz * dt));
        }
        let peak = white.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        white.iter().map(|v| v / peak).collect()
    }

    /// A 1 kHz dataset of the input `x` and the output `y` with uniform white noise of 0.5 %
    /// of its span (RMS) drawn from `rng`; the first 70 % trains.
    pub(super) fn with_noise(x: Vec<f64>, y: &[f64], rng: &mut impl Rng) -> Dataset {
        let (dt, n) = (1e-3, x.len());
        let (lo, hi) = y.iter().fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
        let noise = 0.005 * (hi - lo);
        let output = y.iter().map(|v| v + noise * (rng.random::<f64>() - 0.5) * 12f64.sqrt()).collect();
        Dataset {
            dt,
            time: (0..n).map(|i| i as f64 * dt).collect(),
            input: x,
            output,
            command: None,
            train_end: n * 7 / 10,
            excluded: vec![false; n],
            unusable: Vec::new(),
            rates: None,
            runs: Vec::new(),
        }
    }

    /// Round 1 on a Bouc–Wen base fitted to `data`, as a diagnosis runs it: `f` gets the
    /// problem, the candidates, the round's reference and their ranking.
    pub(super) fn round_one<T>(
        data: &Dataset,
        f: impl FnOnce(&Problem<'_>, &[Candidate], &Fitted, &[rank::Scored]) -> T,
    ) -> T {
        let opts = DiagnoseOptions { model: Some("bouc_wen".into()), ..Default::default() };
        let bases = base::fit_bases(data, &["bouc_wen"], &opts, &crate::progress::NoProgress).unwrap();
        let b = &bases.contenders[0];
        let cutoff = crate::numerics::derivative::CUTOFF_OF_FS / data.dt;
        let prob = Problem::new(data, (b.sim.as_ref(), &b.spec), b.fit.rate_choice, base::rows(data).0, cutoff);
        let current = prob.refit(&[], &[], None, &b.fit.flat, 8).unwrap().0;
        let reference = rank::reference(&prob, &current).unwrap();
        let cands = candidates::all(data, &candidates::classify(data, vec![], None), false, prob.rate_cutoff_hz);
        let (reference, ranked) = rank::rank(&prob, &cands, &reference, &[]).unwrap();
        f(&prob, &cands, &reference, &ranked)
    }

    fn run(data: &Dataset) -> Diagnosis {
        let opts = DiagnoseOptions { model: Some("bouc_wen".into()), ..Default::default() };
        diagnose(data, vec![], None, ("b", "torque"), &opts, &crate::progress::NoProgress).unwrap()
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
    fn a_slow_field_lag_is_named_with_its_time_constant() {
        // A 120 ms lag (eddy currents in thick discs, or a coil's L/R behind a current input)
        // under band-limited noise at 2 Hz, the bench's slowest excitation: searched only to
        // 50 ms (until 2026-11-28), the lag sat at its edge, was impossible, and nothing was named.
        let mut rng = rand::rngs::StdRng::seed_from_u64(17);
        let (dt, n) = (1e-3, 12_000);
        let x: Vec<f64> = band_limited(&mut rng, n, dt, 2.0).iter().map(|v| 0.8 * v).collect();
        let y = bouc_wen_truth(&Transform::Lag { tau_s: 0.12 }.apply(&x, dt), dt);
        let d = run(&with_noise(x, &y, &mut rng));
        let top = d.findings.first().unwrap_or_else(|| panic!("no finding: {:#?}", d.candidates));
        assert_eq!(top.effect, "field_lag", "{:#?}", d.candidates);
        let tau = top.params["tau_s"];
        assert!((0.09..=0.16).contains(&tau), "tau {tau}");
    }

    #[test]
    fn a_yield_stress_levelling_off_is_named_on_the_output_side() {
        // A unipolar field 0.2–1.8; the torque above its floor compressed by
        // u/√(1 + (u/T_s)²) with T_s = 1.5 spans (the RMS change is some 6 % of the span).
        let dt = 1e-3;
        let tone = |t: f64, f: f64, ph: f64| (2.0 * std::f64::consts::PI * f * t + ph).sin();
        let x: Vec<f64> = (0..12_000)
            .map(|i| i as f64 * dt)
            .map(|t| 1.0 + 0.5 * tone(t, 2.0, 0.0) + 0.2 * tone(t, 7.3, 1.0) + 0.1 * tone(t, 13.1, 2.0))
            .collect();
        let m = bouc_wen_truth(&x, dt);
        let (lo, hi) = crate::numerics::stats::min_max(&m);
        let s = 1.5 * (hi - lo);
        let y: Vec<f64> = m.iter().map(|v| lo + (v - lo) / (1.0 + ((v - lo) / s).powi(2)).sqrt()).collect();
        let change = (m.iter().zip(&y).map(|(a, b)| (a - b).powi(2)).sum::<f64>() / m.len() as f64).sqrt();
        assert!(change > 0.03 * (hi - lo), "the effect is {:.1} % of the span", 100.0 * change / (hi - lo));
        let d = run(&with_noise(x, &y, &mut rand::rngs::StdRng::seed_from_u64(7)));
        let top = d.findings.first().expect("a finding");
        assert_eq!(top.effect, "saturation", "{:#?}", d.candidates);
        let t_sat = top.params.get("t_sat").copied().expect("the output-side saturation");
        assert!(t_sat > 0.5 * (hi - lo) && t_sat < 5.0 * (hi - lo), "T_s {t_sat} for a span of {}", hi - lo);
        assert_eq!(top.units.get("t_sat").map(String::as_str), Some("N·m"), "{:?}", top.units);
    }

    #[test]
    fn a_steep_rate_term_read_through_a_12_bit_hall_is_not_a_lag() {
        // Kwok's tanh clutch (seed 000 eq. 11–12: the `tanh` base itself, nothing missing)
        // under band-limited noise, its field read by a 12-bit ADC over ±1 T with half a count
        // of noise. Differentiated at fs/8, the reading's steps jittered tanh(β·ḃ) around
        // ḃ = 0, and a 2–4 ms lag of the input, which smooths them, was named.
        let mut rng = rand::rngs::StdRng::seed_from_u64(21);
        let (dt, n) = (1e-3, 20_000);
        let b: Vec<f64> = band_limited(&mut rng, n, dt, 6.0).iter().map(|v| 0.3 + 0.25 * v).collect();
        let db = crate::numerics::derivative::gradient(&b, dt);
        let y: Vec<f64> = b.iter().zip(&db).map(|(b, d)| 0.8 + 22.0 * b + 0.01 * d + 1.5 * (0.6 * d).tanh()).collect();
        let step = 2.0 / 4096.0;
        let read: Vec<f64> = b
            .iter()
            .map(|v| ((v + 0.5 * step * (rng.random::<f64>() - 0.5) * 12f64.sqrt()) / step).round() * step)
            .collect();
        let data = with_noise(read, &y, &mut rng);
        let opts = DiagnoseOptions { model: Some("tanh".into()), ..Default::default() };
        let d = diagnose(&data, vec![], None, ("b", "torque"), &opts, &crate::progress::NoProgress).unwrap();
        assert!(d.findings.is_empty(), "{:#?}", d.findings);
        assert!(d.notes.iter().any(|n| n.contains("smoothed (zero phase)")), "{:?}", d.notes);
    }

    #[test]
    fn a_damping_that_follows_the_excitation_frequency_is_named_with_its_window() {
        // 30 s of blocks of 1.5 s at 2–6 Hz (phase-continuous), the amplitude (eased in over 50 ms)
        // falling as 1/f so that the rate's amplitude is the same in every block: a term in
        // the rate alone cannot follow the frequency. The clutch's extra damping follows the
        // block's frequency through a 0.4 s first-order memory (known from the design, not
        // estimated), c·(f_mem/f̄ − 1)·ḃ, sized to 4 % of the torque span (RMS).
        let dt = 1e-3;
        let freqs = [2.0, 4.5, 3.0, 6.0, 2.5, 5.0];
        let f_of = |i: usize| freqs[(i as f64 * dt / 1.5) as usize % freqs.len()];
        let (mut phase, mut memory, mut amp) = (0.0f64, f_of(0), 3.0 / f_of(0));
        let (a, ease) = ((-dt / 0.4f64).exp(), (-dt / 0.05f64).exp());
        let mut x = Vec::new();
        let mut f_mem = Vec::new();
        for i in 0..30_000 {
            phase += std::f64::consts::TAU * f_of(i) * dt;
            memory = a * memory + (1.0 - a) * f_of(i);
            amp = ease * amp + (1.0 - ease) * 3.0 / f_of(i);
            x.push(amp * (phase.sin() + 0.1 * (3.1 * phase).sin()));
            f_mem.push(memory);
        }
        let db = crate::numerics::derivative::gradient(&x, dt);
        let f_bar = crate::numerics::stats::mean(&f_mem);
        let term: Vec<f64> = f_mem.iter().zip(&db).map(|(f, d)| (f / f_bar - 1.0) * d).collect();
        let y = bouc_wen_plus(&x, dt, &term, 0.04, crate::numerics::stats::rms);
        let d = run(&with_noise(x, &y, &mut rand::rngs::StdRng::seed_from_u64(11)));
        let top = d.findings.first().unwrap_or_else(|| panic!("no finding: {:#?}", d.candidates));
        assert_eq!(top.effect, "rate_dependence", "{:#?}", d.candidates);
        assert!(top.evidence.label.contains("frequency"), "{}", top.evidence.label);
        let w = top.params.get("window_s").copied().expect("its averaging time");
        assert!((0.1..=3.0).contains(&w), "window {w} s");
        assert!(top.summary.contains(" s)"), "{}", top.summary);
    }

    #[test]
    fn a_loading_branch_lifted_with_the_field_is_an_asymmetry_not_a_rate_term() {
        // The catalog's sigmoid-gated asymmetry: the Bouc–Wen clutch's loading branch alone
        // lifted in proportion to the field above its floor, δ·(b − b_min)·(1 + tanh(ḃ/ε))/2
        // (ε a tenth of the rate's RMS), under band-limited noise on a positive field, sized to
        // 4 % of the torque span (RMS about its mean). Half of it is a static line and a plain
        // direction term a base takes up; the remainder, fitted by the symmetric shape
        // δ·(b − b̄)·sgn ḃ, was beaten by a |ḃ|·ḃ term on two fresh16 recordings.
        let mut rng = rand::rngs::StdRng::seed_from_u64(13);
        let (dt, n) = (1e-3, 12_000);
        let x: Vec<f64> = band_limited(&mut rng, n, dt, 5.0).iter().map(|v| 1.0 + 0.8 * v).collect();
        let db = crate::numerics::derivative::gradient(&x, dt);
        let eps = 0.1 * crate::numerics::stats::rms(&db);
        let x_min = crate::numerics::stats::min_max(&x).0;
        let term: Vec<f64> = x.iter().zip(&db).map(|(x, d)| (x - x_min) * 0.5 * (1.0 + (d / eps).tanh())).collect();
        let y = bouc_wen_plus(&x, dt, &term, 0.04, crate::numerics::stats::std);
        let d = run(&with_noise(x, &y, &mut rng));
        let top = d.findings.first().unwrap_or_else(|| panic!("no finding: {:#?}", d.candidates));
        assert_eq!(top.effect, "asymmetry", "{:#?}", d.candidates);
        assert!(top.summary.contains("loading branch alone"), "{}", top.summary);
        let delta = top.params.get(candidates::LOADING_TERM).copied().expect("the loading-branch term");
        assert!(delta > 0.0, "δ_l = {delta}: the loading branch was lifted");
    }

    #[test]
    fn nothing_missing_gives_no_finding() {
        let d = run(&recording(None, 2));
        assert!(d.findings.is_empty(), "{:#?}", d.findings);
        assert!(!d.candidates.is_empty(), "every candidate is still tested");
        // The header's reference is what round 1's candidates were judged against, and with
        // nothing found the diagnosis ends with it (not with the fit alone).
        let judged = d.candidates.iter().map(|c| c.heldout_r_rmse_before);
        assert!(
            judged.clone().all(|b| b == d.reference_heldout.r_rmse),
            "{:?} {:?}",
            d.reference_heldout,
            judged.collect::<Vec<_>>()
        );
        assert_eq!(d.final_heldout.r_rmse, d.reference_heldout.r_rmse);
    }
}
