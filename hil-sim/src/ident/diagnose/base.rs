//! Stage 1 of a diagnosis, the base model: fitted on the training part with the channels
//! as recorded (`DelayChoice::Off`: a time shift between channels is a finding, not
//! something to absorb silently). `auto` fits every seed model ([`AUTO_BASES`]) and keeps
//! the one with the lowest held-out RMSE.

use model_core::{models, Model};
use rayon::prelude::*;

use super::options::{DiagnoseError, DiagnoseOptions};
use crate::ident::fit::simulate::Simulator;
use crate::ident::fit::{fit, Dataset, DelayChoice, FitOptions, FitResult};
use crate::models::search::{ModelSpec, Strategy};
use crate::progress::Progress;

/// The seed models `auto` (no base model given) chooses among: every parametric model of the papers
/// (the operator and data-driven models describe a loop without naming physics) but Spencer's:
/// its inner spring–dashpot stage is a first-order lag of the input, so as a base it absorbs a
/// `field_lag` it would then never name, and its fit is half the time of all the others
/// together (it stays a base when asked for, `--model spencer`).
pub const AUTO_BASES: &[&str] = &[
    models::algebraic::Registered::ID,
    models::bouc_wen::Registered::ID,
    models::lugre::Registered::ID,
    models::tanh::Registered::ID,
    models::dahl::Registered::ID,
    models::bingham::Registered::ID,
    models::arctan::Registered::ID,
    models::arctan_inertia::Registered::ID,
    models::trig::Registered::ID,
];

/// Seed models of one structure: a group's best member stands for it.
pub const GROUPS: &[&[&str]] = &[
    &["tanh"],
    &["dahl", "lugre"],
    &["bouc_wen", "spencer"],
    &["algebraic"],
    &["bingham", "arctan", "arctan_inertia", "trig"],
];
/// Most contenders, the best-fitting base included.
pub const MAX: usize = 4;
/// A contender's held-out RMSE is at most this multiple of the best one's.
pub const WITHIN: f64 = 2.5;
/// The seed model that is also a contender with play operators (`contenders.rs`): the stateless
/// algebraic model, so that the loop is the operators' alone.
pub const PLAY_HOST: &str = <model_core::models::algebraic::Registered as model_core::Model>::ID;
/// The contenders among `scored` (model id and held-out RMSE, best first): indices into it,
/// the best first.
pub fn pick(scored: &[(&str, f64)]) -> Vec<usize> {
    let Some(&(first, best)) = scored.first() else { return Vec::new() };
    let group = |id: &str| GROUPS.iter().position(|g| g.contains(&id));
    let mut seen = vec![group(first)];
    let mut keep = vec![0];
    for (k, &(id, s)) in scored.iter().enumerate().skip(1) {
        let g = group(id);
        if keep.len() >= MAX || s > WITHIN * best || g.is_none() || seen.contains(&g) {
            continue;
        }
        seen.push(g);
        keep.push(k);
    }
    keep
}

/// Levenberg–Marquardt iterations of the base model's fit.
const LM_ITERATIONS: usize = 30;
/// Rows this close to either end (s, plus two samples) are left out of the refits and the
/// scores: delays and filters read past the ends.
const MARGIN_S: f64 = 0.02;

/// A fitted base model and what its refits need.
pub struct Base {
    pub fit: FitResult,
    pub sim: Box<dyn Simulator>,
    pub spec: ModelSpec,
}

/// Every base model fitted, the contenders among them and what failed.
pub struct Bases {
    /// The contenders ([`pick`]), the best held-out one first.
    pub contenders: Vec<Base>,
    /// With `auto`: the seed model that is also tried with play operators
    /// ([`PLAY_HOST`]), when it could be fitted.
    pub play_host: Option<Base>,
    /// Every base model fitted, with its held-out R-RMSE.
    pub tried: Vec<(String, f64)>,
    /// The base models `auto` could not fit, with why.
    pub failed: Vec<String>,
}

/// The base models to try: the one asked for, or [`AUTO_BASES`].
pub fn choices(opts: &DiagnoseOptions) -> Vec<&str> {
    match &opts.model {
        Some(m) => vec![m.as_str()],
        None => AUTO_BASES.to_vec(),
    }
}

/// Fit every base of `bases` side by side (one progress step each); the best held-out one and the other
/// contenders ([`pick`]) are made ready for the refits.
pub fn fit_bases(
    data: &Dataset,
    bases: &[&str],
    opts: &DiagnoseOptions,
    progress: &dyn Progress,
) -> Result<Bases, DiagnoseError> {
    let fit_opts = FitOptions {
        rate: opts.rate,
        delay: DelayChoice::Off,
        swarm: crate::ident::fit::global::SwarmOptions { seed: opts.seed, ..Default::default() },
        lm_iterations: LM_ITERATIONS,
        ..Default::default()
    };
    // Side by side: each fit is deterministic on its own, and one fit alone kept two cores
    // busy only 70 % of its time. The results are read in the order of `bases`.
    let results: Vec<_> = bases
        .par_iter()
        .map(|id| {
            progress.message(&format!("fitting {id}"));
            let r = fit(id, data, &fit_opts).map(|r| {
                let alt = second_basin(data, &r, &fit_opts);
                (r, alt)
            });
            progress.advance(1);
            r
        })
        .collect();
    let mut fits: Vec<FitResult> = Vec::new();
    let mut errors = Vec::new();
    let mut swarm_only = Vec::new();
    for (id, r) in bases.iter().zip(results) {
        match r {
            Ok((r, alt)) => {
                swarm_only.extend(alt);
                fits.push(r);
            }
            Err(e) if opts.model.is_some() => return Err(e.into()),
            Err(e) => errors.push(format!("the base model {id} could not be fitted: {e}")),
        }
    }
    let score = |r: &FitResult| r.heldout_unflagged.unwrap_or(r.heldout).rmse;
    let tried: Vec<(String, f64)> =
        fits.iter().map(|r| (r.model.clone(), r.heldout_unflagged.unwrap_or(r.heldout).r_rmse)).collect();
    for r in fits.iter().filter(|r| !score(r).is_finite()) {
        errors.push(format!("the base model {} was fitted but its held-out prediction is not finite", r.model));
    }
    let mut fits: Vec<FitResult> = fits.into_iter().filter(|r| score(r).is_finite()).collect();
    fits.sort_by(|a, b| score(a).total_cmp(&score(b)));
    if fits.is_empty() {
        return Err(DiagnoseError::NoBase(errors.join("; ")));
    }
    let scored: Vec<(&str, f64)> = fits.iter().map(|r| (r.model.as_str(), score(r))).collect();
    let keep = pick(&scored);
    let host = fits.iter().find(|r| opts.model.is_none() && r.model == PLAY_HOST).cloned();
    let held = opts.model.is_none();
    let play_host = host.and_then(|f| ready(data, f, held).ok());
    let mut contenders = Vec::with_capacity(keep.len());
    for (k, fit) in fits.into_iter().enumerate().filter(|(k, _)| keep.contains(k)) {
        match ready(data, fit, held) {
            Ok(b) => contenders.push(b),
            // The best base must be refittable; another contender that is not is left out.
            Err(e) if k == 0 => return Err(e),
            Err(_) => {}
        }
    }
    // A contender's fit from the swarm alone, in another basin, contends beside it.
    for alt in swarm_only {
        if contenders.iter().any(|b| b.fit.model == alt.model) {
            contenders.extend(ready(data, alt, held).ok());
        }
    }
    Ok(Bases { contenders, play_host, tried, failed: errors })
}

/// For a model with affine parameters (tanh), whose global search also starts from a grid
/// ([`crate::ident::fit::separable`]): its fit without the grid, when that ends in another
/// basin (outputs apart by more than [`BASIN_APART`] of the output's spread). The grid finds
/// the lowest training error of the model alone; on a clutch with a concealed rate term that
/// is often a rate gain bent to absorb the term, and the swarm's basin, with the term added,
/// fits far better (a Kwok clutch with a `|ḃ|·ḃ` term: held-out 0.76 % with the grid's base
/// and the term, 0.40 % with the swarm's).
fn second_basin(data: &Dataset, first: &FitResult, fit_opts: &FitOptions) -> Option<FitResult> {
    let affine = crate::models::host(&first.model).is_some_and(|h| !h.affine.is_empty());
    if !affine {
        return None;
    }
    let alt = fit(&first.model, data, &FitOptions { separable: false, ..*fit_opts }).ok()?;
    let spread = data.scales().y;
    let diff: Vec<f64> = alt.output.iter().zip(&first.output).map(|(a, b)| a - b).collect();
    let apart = crate::numerics::stats::rms(&diff) > BASIN_APART * spread;
    apart.then_some(alt)
}

/// Two fits of one model whose outputs differ by more than this fraction of the output's
/// spread (RMS) are in different basins.
const BASIN_APART: f64 = 1e-3;

/// The simulator and search space of the fitted base `fit`; with `held` (`auto`), the
/// [`NO_BEND_OVER`] parameters held ≥ 0.
fn ready(data: &Dataset, fit: FitResult, held: bool) -> Result<Base, DiagnoseError> {
    let id = fit.model.clone();
    let sim = crate::ident::fit::simulate::simulator(&id, data.dt as f32)
        .ok_or_else(|| DiagnoseError::NotParametric(id.clone()))?;
    // The refits search the box of the variant the fit kept (its held values included).
    let scales = data.scales();
    let spec = crate::models::host(&id)
        .and_then(|h| h.at_variant(&h.spec(&scales, Some(fit.rate_choice))?, fit.variant, &scales))
        .ok_or_else(|| DiagnoseError::NotParametric(id.clone()))?;
    if !matches!(spec.strategy, Strategy::Linear | Strategy::Local | Strategy::Global) {
        return Err(DiagnoseError::NotParametric(id));
    }
    Ok(Base { fit, sim, spec: if held { without_bend_over(spec) } else { spec } })
}

/// Parameters (model id, name) whose negative values bend a base's static curve over at
/// high input: the algebraic model's `α·|B|·B³` with α < 0 flattens the torque at the top
/// of the field as a saturation does, and with play operators beside it absorbed every
/// concealed saturation it was the base of. With `auto` the refits hold them ≥ 0, as the
/// level term's β ([`super::level_map`]): a curve levelling off is left for the rounds to
/// name. A base the user names (`--model algebraic`) is taken as given, its curve free to
/// bend over: `simulate --base algebraic`'s own truth has α < 0 (a clutch's curve fitted
/// by it), and on such a recording a held α named its own curve a saturation.
pub const NO_BEND_OVER: &[(&str, &str)] = &[(models::algebraic::Registered::ID, "alpha")];

/// `spec` with the [`NO_BEND_OVER`] parameters held ≥ 0.
fn without_bend_over(mut spec: ModelSpec) -> ModelSpec {
    let id = spec.id;
    for p in spec.params.iter_mut().filter(|p| NO_BEND_OVER.contains(&(id, p.name))) {
        p.lo = p.lo.max(0.0);
        p.hi = p.hi.max(p.lo);
        p.start = p.start.clamp(p.lo, p.hi);
    }
    spec
}

/// The training and held-out (unflagged) rows away from the ends.
pub fn rows(data: &Dataset) -> (Vec<usize>, Vec<usize>) {
    let inside = inside(data);
    let train = data.train_rows().into_iter().filter(&inside).collect();
    let held = data.heldout_unflagged().into_iter().filter(&inside).collect();
    (train, held)
}

/// Whether a row is [`MARGIN_S`] (and two samples) away from both ends of the recording.
fn inside(data: &Dataset) -> impl Fn(&usize) -> bool {
    let n = data.len();
    let margin = (MARGIN_S / data.dt).ceil() as usize + 2;
    move |i: &usize| *i >= margin && *i + margin < n
}

/// The models start from rest: the reversed split's head is scored from this long after a
/// run's start (s), or from a third of the head if that is sooner. Scored from the start,
/// the first of a head's ten blocks carried up to 10⁴ times the drop of the others, the
/// start-up transient of whichever fit happened to begin closer to the recording's state.
const WARM_UP_S: f64 = 1.0;

/// The split [`rows`] makes, reversed ([`super::replicate`]): in each run, a head as long as
/// its held-out tail is held out and the rest trains; the head is scored after the models'
/// start-up ([`WARM_UP_S`]).
pub fn reversed_rows(data: &Dataset) -> (Vec<usize>, Vec<usize>) {
    let inside = inside(data);
    let (mut train, mut held) = (Vec::new(), Vec::new());
    for r in data.spans() {
        let head_end = r.start + (r.end - r.train_end);
        let warm_up = ((WARM_UP_S / data.dt) as usize).min((head_end - r.start) / 3);
        held.extend((r.start + warm_up..head_end).filter(|i| inside(i) && !data.flagged(*i)));
        train.extend((head_end..r.end).filter(|i| inside(i) && data.enters_fit(*i)));
    }
    (train, held)
}

/// A split of the held-out rows and the rows that train on them.
pub type Split = (Vec<usize>, Vec<usize>);

/// The two interleaved splits where a term acts ([`super::acting`]): in the run where it
/// fits, the stretch as long as that run's held-out tail over which `weight` (what the term
/// changes in the prediction, per sample) has the most energy, from the models' start-up on
/// ([`WARM_UP_S`]), is cut into ten pieces; the first split holds out the even pieces, the
/// second the odd ones, and every other row of every run trains. The splits and the stretch's
/// first and last sample; `None` when no run has room for it.
pub fn interleaved_rows(data: &Dataset, weight: &[f64]) -> Option<([Split; 2], (usize, usize))> {
    let inside = inside(data);
    let mut energy = vec![0.0; weight.len() + 1];
    for (i, w) in weight.iter().enumerate() {
        let counted = inside(&i) && !data.flagged(i);
        energy[i + 1] = energy[i] + if counted { w * w } else { 0.0 };
    }
    let pieces = super::significance::BLOCKS;
    let mut best: Option<(f64, usize, usize)> = None;
    for r in data.spans() {
        let len = r.end - r.train_end;
        let first = r.start + (WARM_UP_S / data.dt) as usize;
        if len < 4 * pieces || first + len > r.end.min(weight.len()) {
            continue;
        }
        for a in first..=r.end - len {
            let e = energy[a + len] - energy[a];
            if best.is_none_or(|(b, _, _)| e > b) {
                best = Some((e, a, a + len));
            }
        }
    }
    let (_, a, b) = best?;
    let piece = |i: usize| (a..b).contains(&i).then(|| (i - a) * pieces / (b - a));
    let split = |parity: usize| -> Split {
        let out = |i: &usize| piece(*i).is_some_and(|k| k % 2 == parity);
        let held = (a..b).filter(|i| out(i) && inside(i) && !data.flagged(*i)).collect();
        let train = (0..data.len()).filter(|i| !out(i) && inside(i) && data.enters_fit(*i)).collect();
        (held, train)
    };
    Some(([split(0), split(1)], (a, b - 1)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_algebraic_base_may_not_bend_its_curve_over_and_the_others_keep_their_box() {
        let data = crate::ident::diagnose::tests::recording(None, 3);
        let spec = |id: &str| crate::models::host(id).and_then(|h| h.spec(&data.scales(), None)).unwrap();
        let (raw, held) = (spec("algebraic"), without_bend_over(spec("algebraic")));
        let param = |s: &ModelSpec, name: &str| s.params.iter().find(|p| p.name == name).cloned().unwrap();
        assert!(param(&raw, "alpha").lo < 0.0);
        let alpha = param(&held, "alpha");
        assert!(alpha.lo == 0.0 && alpha.hi == param(&raw, "alpha").hi && alpha.start >= 0.0);
        assert_eq!(param(&held, "k"), param(&raw, "k"));
        assert_eq!(without_bend_over(spec("bouc_wen")).params, spec("bouc_wen").params);
    }

    /// The refits search the box of the variant the fit kept: `n` held at 1 for Bouc–Wen's
    /// `n = 1` variant (the model's own spec holds it at 2).
    #[test]
    fn a_base_is_refitted_on_the_variant_its_fit_kept() {
        let data = crate::ident::diagnose::tests::recording(None, 3);
        let opts = FitOptions { delay: DelayChoice::Off, lm_iterations: 4, ..Default::default() };
        let fitted = fit("bouc_wen", &data, &opts).unwrap();
        let n_of = |variant: usize| {
            let base = ready(&data, FitResult { variant, ..fitted.clone() }, true).unwrap();
            base.spec.params.iter().find(|p| p.name == "n").map(|p| (p.fixed, p.start)).unwrap()
        };
        assert_eq!(n_of(0), (true, 2.0));
        assert_eq!(n_of(1), (true, 1.0));
    }

    #[test]
    fn the_reversed_split_holds_out_the_head_as_long_as_the_tail() {
        let data = crate::ident::diagnose::tests::recording(None, 3);
        let (train, held) = rows(&data);
        let (r_train, r_held) = reversed_rows(&data);
        let margin = (MARGIN_S / data.dt).ceil() as usize + 2;
        // 12 000 samples at 1 kHz, the last 3 600 held out (the end's margin left out): the
        // first 3 600 are, and score after the first second.
        assert_eq!((held.len(), r_held.len()), (3600 - margin, 2600));
        assert_eq!(r_held.first().copied(), Some(1000));
        assert_eq!(r_held.last().copied(), Some(3599));
        assert_eq!(r_train.first().copied(), Some(3600));
        assert_eq!(r_train.len(), train.len());
        assert!(r_held.iter().all(|i| r_train.binary_search(i).is_err()));
    }

    #[test]
    fn one_contender_per_structure_close_to_the_best() {
        let scored = [
            ("dahl", 1.0),
            ("lugre", 1.01),
            ("bouc_wen", 1.2),
            ("spencer", 1.3),
            ("bingham", 1.9),
            ("tanh", 2.0),
            ("algebraic", 2.4),
            ("trig", 2.6),
        ];
        // lugre shares dahl's structure, spencer bouc_wen's; at most four.
        assert_eq!(pick(&scored), vec![0, 2, 4, 5]);
        assert_eq!(pick(&scored[..1]), vec![0]);
        assert!(pick(&[]).is_empty());
        // trig is beyond 2.5× the best.
        assert_eq!(pick(&[("dahl", 1.0), ("trig", 2.6), ("tanh", 1.2)]), vec![0, 2]);
    }
}
