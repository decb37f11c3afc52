//! The model a diagnosis refits: the base model (parameters θ) fed a transformed input,
//! plus terms linear in their coefficients β,
//!
//! ```text
//! ŷ(t) = m_θ(T(x))(t) + Σ_k β_k · φ_k(t),      φ_k = v_k,  m_θ · v_k  or  g_k(T_k(x))
//! ```
//!
//! `T` chains the input transforms the catalog names (delay, first-order lag, saturating
//! map, offset); the terms are the additive ones (`c·|ẋ|ẋ`, `m·ẍ`, `c_ω·ω`, …) and the
//! multiplicative ones, a parameter scaled by a slow or auxiliary signal (`m·(θ − θ̄)`).
//! The base's own terms that are maps of the input (play operators, the level power:
//! [`InputMap`]) are made again from `T(x)` at every refit: the field a candidate lags or
//! delays is the field the whole base responds to, and the plays see it saturated too.
//!
//! A refit is a damped Gauss–Newton step on θ jointly with the least-squares β: the base
//! model's Jacobian by forward differences through the f32 core (one run per free
//! parameter, in parallel), the normal equations solved on the training rows, the step
//! halved until the true (nonlinear) training cost drops, then β solved again at the new
//! θ. The reference the gain is measured against is refitted the same way without the new
//! term, so a gain is never the extra Gauss–Newton step.

use rayon::prelude::*;

use super::fed::{Fed, Feeds};
use super::projection::{self, Projection};
use super::runs::Runs;
use super::transform::Transform;
use crate::ident::fit::simulate::{kinematics, kinematics_given, Simulator};
use crate::ident::fit::Dataset;
use crate::models::search::{ModelSpec, Spacing};
use crate::models::RateSpec;

/// One term linear in its coefficient.
#[derive(Clone, Debug)]
pub struct Term {
    /// Name of the coefficient in the finding's `params`.
    pub name: String,
    /// `v_k` (one value per sample; empty for [`TermKind::OutputSaturation`]).
    pub values: Vec<f64>,
    pub kind: TermKind,
    /// When the values are a map of the input: the map and its values on the recorded input.
    /// Made again from the transformed input at every refit, so that an input transform
    /// reaches the term as it reaches the base model (most refits transform nothing: then
    /// the recorded values are copied, not made again).
    pub of_input: Option<(InputMap, std::sync::Arc<Vec<f64>>)>,
}

/// A term that is part of the base model's response to the input (the play operators, the
/// level power): the field a candidate lags or delays is the field this term responds to as
/// well, and the plays see a saturated or offset field too.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum InputMap {
    /// A play operator of radius `radius` (input units), [`super::play::play`].
    Play { radius: f64 },
    /// `x_ref·sgn(x)·|x/x_ref|^p`, [`super::level_map`].
    LevelPower { x_ref: f64, p: f64 },
    /// `x³/x_ref²`, an odd cubic of the input ([`super::contenders::plays`]); its weight is
    /// held ≥ 0 ([`Term::at_least_zero`]).
    Cube { x_ref: f64 },
}

impl InputMap {
    /// The term's values for the input `x`.
    pub fn values(&self, x: &[f64]) -> Vec<f64> {
        match *self {
            Self::Play { radius } => super::play::play(x, radius),
            Self::LevelPower { x_ref, p } => x.iter().map(|v| x_ref * v.signum() * (v.abs() / x_ref).powf(p)).collect(),
            Self::Cube { x_ref } => x.iter().map(|v| v * (v / x_ref).powi(2)).collect(),
        }
    }

    /// Whether the term follows a transform `t` of the input. The level power follows only
    /// the transforms in time (delay, lags): its exponent is fitted once, before the rounds,
    /// and a saturating map or an offset composed with it is a second curvature that fits
    /// whatever shape its one exponent missed (on fresh12's nulls, a power-law truth's
    /// exponent fitted 1.8–2.0 for 1.4, then "saturated" back: 2 false alarms).
    pub fn follows(&self, t: &Transform) -> bool {
        match self {
            Self::Play { .. } | Self::Cube { .. } => true,
            Self::LevelPower { .. } => {
                matches!(
                    t,
                    Transform::Delay { .. } | Transform::Lag { .. } | Transform::Lag2 { .. } | Transform::Smooth { .. }
                )
            }
        }
    }
}

/// How a term's column is made from its values and the base model's output `m`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TermKind {
    /// `v_k`.
    Additive,
    /// `m_θ · v_k` (a parameter of the base model scaled by `v_k`).
    TimesModel,
    /// The model's output above its floor compressed, less itself: with `u = m − min m`,
    /// `min m + u/√(1 + (u/t_sat)²) − m` (the fluid's yield stress saturating, so the
    /// torque flattens at high field whatever the field does; β ≈ 1 for exactly that map).
    OutputSaturation { t_sat: f64 },
}

impl Term {
    pub fn additive(name: impl Into<String>, values: Vec<f64>) -> Self {
        Self { name: name.into(), values, kind: TermKind::Additive, of_input: None }
    }
    /// An additive term `map(x)` of the input `x` (the recorded one: a refit makes it again
    /// from the transformed input).
    pub fn of_input(name: impl Into<String>, map: InputMap, x: &[f64]) -> Self {
        let values = map.values(x);
        let recorded = std::sync::Arc::new(values.clone());
        Self { name: name.into(), values, kind: TermKind::Additive, of_input: Some((map, recorded)) }
    }
    pub fn scaling(name: impl Into<String>, values: Vec<f64>) -> Self {
        Self { name: name.into(), values, kind: TermKind::TimesModel, of_input: None }
    }
    pub fn output_saturation(name: impl Into<String>, t_sat: f64) -> Self {
        Self { name: name.into(), values: Vec::new(), kind: TermKind::OutputSaturation { t_sat }, of_input: None }
    }
    /// The radius of its play operator, when it is one of the input.
    pub fn play_radius(&self) -> Option<f64> {
        self.of_input.as_ref().and_then(|(m, _)| if let InputMap::Play { radius } = m { Some(*radius) } else { None })
    }
    /// Whether its column is its values, the same whatever the base model predicts.
    pub fn is_additive(&self) -> bool {
        matches!(self.kind, TermKind::Additive)
    }
    /// A copy whose values, when they are a map of the input, are left empty for
    /// [`Problem::through`] to make (not copied only to be replaced).
    fn to_make_again(&self) -> Term {
        let values = if self.of_input.is_some() { Vec::new() } else { self.values.clone() };
        Term { name: self.name.clone(), values, kind: self.kind, of_input: self.of_input.clone() }
    }
    /// Whether its weight is held ≥ 0: the cubic of the input, which would otherwise bend
    /// the base's curve over and take up a saturation.
    pub fn at_least_zero(&self) -> bool {
        matches!(self.of_input, Some((InputMap::Cube { .. }, _)))
    }
    fn column(&self, m: &[f64]) -> std::borrow::Cow<'_, [f64]> {
        use std::borrow::Cow;
        Cow::Owned(match self.kind {
            TermKind::Additive => return Cow::Borrowed(&self.values),
            TermKind::TimesModel => self.values.iter().zip(m).map(|(v, m)| v * m).collect(),
            TermKind::OutputSaturation { t_sat } => {
                let floor = crate::numerics::stats::min_max(m).0;
                let s = t_sat.max(1e-300);
                m.iter()
                    .map(|m| {
                        let u = m - floor;
                        u / (1.0 + (u / s).powi(2)).sqrt() - u
                    })
                    .collect()
            }
        })
    }
}

/// What stays fixed across every refit of one diagnosis.
pub struct Problem<'a> {
    pub data: &'a Dataset,
    pub sim: &'a dyn Simulator,
    pub spec: &'a ModelSpec,
    pub rate: RateSpec,
    /// Training rows the refit uses (flagged samples and delay-uncovered edges left out).
    pub train: Vec<usize>,
    /// Cutoff (Hz) of the zero-phase rate of the given rates
    /// ([`crate::numerics::derivative::content_cutoff`]): a transformed input gets its rate the same way.
    pub rate_cutoff_hz: f64,
    /// The feeds made so far ([`super::fed`]), shared with [`Problem::on_rows`]'s problems
    /// (and [`Problem::sharing`]'s)…
    feeds: std::sync::Arc<Feeds>,
    /// …and the base model's outputs run last ([`super::runs`]).
    runs: std::sync::Arc<Runs>,
    /// Standard deviation of the output on the training rows: the refits' cost scale.
    scale: f64,
}

/// Standard deviation of `data`'s output on the rows `train`.
fn spread(data: &Dataset, train: &[usize]) -> f64 {
    let ys: Vec<f64> = train.iter().filter_map(|&i| data.output.get(i).copied()).collect();
    crate::numerics::stats::std(&ys)
}

/// A refitted augmented model.
#[derive(Clone, Debug)]
pub struct Fitted {
    pub transforms: Vec<Transform>,
    pub terms: Vec<Term>,
    pub theta: Vec<f64>,
    pub beta: Vec<f64>,
    /// The base model's output (through the transforms) over the whole recording.
    pub model: Vec<f64>,
    /// The full prediction over the whole recording.
    pub pred: Vec<f64>,
    /// Mean squared error on the training rows.
    pub train_mse: f64,
}

impl Fitted {
    /// Free coefficients this model adds to the base model's.
    pub fn extra_params(&self) -> usize {
        self.terms.len() + self.transforms.len()
    }
}

/// Builds what a candidate adds at its value `g`: an input transform and/or terms.
pub type PieceFn<'a> = dyn Fn(f64) -> (Option<Transform>, Vec<Term>) + Sync + 'a;

/// The tunable value of a candidate for [`Problem::refit`]: its builder, its start and box.
pub struct Tune<'a> {
    pub build: &'a PieceFn<'a>,
    pub start: f64,
    pub lo: f64,
    pub hi: f64,
    /// Searched on a log scale (time constants, levels).
    pub log: bool,
}

/// The augmented model as a [`Simulator`] for the fit's Levenberg–Marquardt: parameters are
/// the base model's θ followed by the candidate's value `g` (when it has one); β is solved
/// by least squares inside every run (variable projection), so the optimiser only sees θ
/// and `g`.
struct AugSim<'p, 'a> {
    prob: &'p Problem<'a>,
    transforms: &'p [Transform],
    terms: &'p [Term],
    tune: Option<&'p Tune<'p>>,
    /// Kinematics and the candidate's terms for the last [`CACHED`] values of `g` asked for
    /// (a Jacobian asks for `g` and `g + h` side by side), the latest first.
    cache: std::sync::Mutex<Vec<CachedPiece>>,
}

/// Tuning values whose kinematics an [`AugSim`] keeps.
const CACHED: usize = 2;

/// Kinematics, transforms, terms and their least squares at one tuning value.
type Piece = (std::sync::Arc<Fed>, Vec<Transform>, Vec<Term>, Projection);
type CachedPiece = (u64, std::sync::Arc<Piece>);
/// Base output, β, prediction, its mean squared error, transforms and terms (`AugSim::full`).
type Full = (Vec<f64>, Vec<f64>, Vec<f64>, f64, Vec<Transform>, Vec<Term>);

impl AugSim<'_, '_> {
    fn n_base(&self) -> usize {
        self.prob.sim.n_params()
    }
    /// Kinematics, transforms and terms at `g`.
    fn at(&self, g: f64) -> Option<std::sync::Arc<Piece>> {
        if let Ok(c) = self.cache.lock() {
            if let Some((_, v)) = c.iter().find(|(k, _)| *k == g.to_bits()) {
                return Some(std::sync::Arc::clone(v));
            }
        }
        let mut transforms = self.transforms.to_vec();
        let mut terms: Vec<Term> = self.terms.iter().map(Term::to_make_again).collect();
        if let Some(t) = self.tune {
            let (tr, extra) = (t.build)(g);
            transforms.extend(tr);
            terms.extend(extra);
        }
        let fed = self.prob.fed(&transforms)?;
        let terms = self.prob.through(terms, &transforms, &fed.x);
        let projection = self.prob.projection(&terms);
        let v = std::sync::Arc::new((fed, transforms, terms, projection));
        if let Ok(mut c) = self.cache.lock() {
            c.insert(0, (g.to_bits(), std::sync::Arc::clone(&v)));
            c.truncate(CACHED);
        }
        Some(v)
    }
    /// The training MSE at `p` ([`AugSim::full`]'s), the base model run up to the last
    /// training row only (so a run that diverges after it no longer fails). A term whose
    /// column depends on the whole output (the output's saturation, from its floor) gets
    /// the whole run.
    fn train_mse(&self, p: &[f64]) -> Option<f64> {
        let theta = p.get(..self.n_base())?;
        let piece = self.at(p.get(self.n_base()).copied().unwrap_or(0.0))?;
        let (fed, transforms, terms, projection) = &*piece;
        if terms.iter().any(|t| matches!(t.kind, TermKind::OutputSaturation { .. })) {
            return self.full(p).map(|f| f.3);
        }
        let mut m = vec![0.0; self.prob.train.last().map_or(0, |&i| i + 1)];
        if !self.prob.run_into(theta, transforms, fed, &mut m) {
            return None;
        }
        self.prob.add_terms(terms, projection, &mut m, true).map(|(_, mse)| mse)
    }
    /// The base output, β and the prediction over the whole recording for `p`.
    fn full(&self, p: &[f64]) -> Option<Full> {
        let theta = p.get(..self.n_base())?;
        let g = p.get(self.n_base()).copied().unwrap_or(0.0);
        let piece = self.at(g)?;
        let (fed, transforms, terms, projection) = &*piece;
        let m = self.prob.run_fed(theta, transforms, fed)?;
        let mut pred = m.clone();
        let (beta, mse) = self.prob.add_terms(terms, projection, &mut pred, true)?;
        Some((m, beta, pred, mse, transforms.clone(), terms.clone()))
    }
}

impl Simulator for AugSim<'_, '_> {
    fn id(&self) -> &'static str {
        self.prob.sim.id()
    }
    fn n_params(&self) -> usize {
        self.n_base() + usize::from(self.tune.is_some())
    }
    fn valid(&self, p: &[f64]) -> bool {
        p.get(..self.n_base()).is_some_and(|t| self.prob.sim.valid(t))
    }
    fn run(&self, p: &[f64], _kin: &[model_core::Kin], out: &mut [f64]) -> bool {
        // Only the samples the objective scores (up to its last training row).
        let (Some(theta), Some(piece)) =
            (p.get(..self.n_base()), self.at(p.get(self.n_base()).copied().unwrap_or(0.0)))
        else {
            return false;
        };
        let (fed, transforms, terms, projection) = &*piece;
        // The base model's output, then the terms added to it, in `out` itself.
        if !self.prob.run_into(theta, transforms, fed, out)
            || self.prob.add_terms(terms, projection, out, false).is_none()
        {
            return false;
        }
        out.iter().all(|v| v.is_finite())
    }
}

impl<'a> Problem<'a> {
    /// The refits of `sim` (its search space `spec`, rate estimator `rate`) on `data`,
    /// trained on the rows `train`; `rate_cutoff_hz` as [`Problem::rate_cutoff_hz`].
    pub fn new(
        data: &'a Dataset,
        (sim, spec): (&'a dyn Simulator, &'a ModelSpec),
        rate: RateSpec,
        train: Vec<usize>,
        rate_cutoff_hz: f64,
    ) -> Self {
        let (feeds, runs) = Default::default();
        let scale = spread(data, &train);
        Problem { data, sim, spec, rate, train, rate_cutoff_hz, feeds, runs, scale }
    }

    /// The same problem with the feeds of `feeds` ([`super::fed`]): those of other problems
    /// on the same recording and rate cutoff (another base model's).
    pub fn sharing(self, feeds: &std::sync::Arc<Feeds>) -> Self {
        Problem { feeds: std::sync::Arc::clone(feeds), ..self }
    }

    /// The same problem trained on `train` instead (another split of the recording).
    pub fn on_rows(&self, train: Vec<usize>) -> Problem<'a> {
        let (data, sim, spec, rate, rate_cutoff_hz) = (self.data, self.sim, self.spec, self.rate, self.rate_cutoff_hz);
        let (feeds, runs) = (std::sync::Arc::clone(&self.feeds), std::sync::Arc::clone(&self.runs));
        let scale = spread(data, &train);
        Problem { data, sim, spec, rate, train, rate_cutoff_hz, feeds, runs, scale }
    }

    /// The base model's output for `theta` fed the transformed input (`None` if it diverges).
    pub fn run(&self, theta: &[f64], transforms: &[Transform]) -> Option<Vec<f64>> {
        let fed = self.fed(transforms)?;
        self.run_fed(theta, transforms, &fed)
    }

    /// The base model's output for `theta` fed `fed` (the input through `transforms`), over
    /// the whole recording (`None` if it diverges).
    fn run_fed(&self, theta: &[f64], transforms: &[Transform], fed: &Fed) -> Option<Vec<f64>> {
        let mut out = vec![0.0; fed.kin.len()];
        self.run_into(theta, transforms, fed, &mut out).then_some(out)
    }

    /// The same over the first `out.len()` samples, into `out`: kept or run ([`super::runs`]).
    fn run_into(&self, theta: &[f64], transforms: &[Transform], fed: &Fed, out: &mut [f64]) -> bool {
        let Some(kin) = fed.kin.get(..out.len()) else { return false };
        self.runs.run_into(transforms, theta, out, |out| self.sim.run(theta, kin, out))
    }

    /// The recorded input through `transforms`.
    pub(super) fn transformed(&self, transforms: &[Transform]) -> Vec<f64> {
        let Some((first, rest)) = transforms.split_first() else { return self.data.input.clone() };
        let mut x = first.apply(&self.data.input, self.data.dt);
        for t in rest {
            x = t.apply(&x, self.data.dt);
        }
        x
    }

    /// `terms` with the maps of the input made again from the recorded input through the
    /// `transforms` each follows ([`InputMap::follows`]; `x`: through all of them).
    pub(super) fn through(&self, mut terms: Vec<Term>, transforms: &[Transform], x: &[f64]) -> Vec<Term> {
        if !transforms.is_empty() {
            // The play operators follow every transform: made side by side, in one pass.
            let radii: Vec<f64> = terms.iter().filter_map(Term::play_radius).collect();
            let mut made = super::play::plays(x, &radii).into_iter();
            terms
                .iter_mut()
                .filter(|t| t.play_radius().is_some())
                .for_each(|t| t.values = made.next().unwrap_or_default());
        }
        for t in &mut terms {
            let Some((map, recorded)) = &t.of_input else { continue };
            if matches!(map, InputMap::Play { .. }) && !transforms.is_empty() {
                continue;
            }
            t.values = if !transforms.iter().any(|tr| map.follows(tr)) {
                recorded.as_ref().clone()
            } else if transforms.iter().all(|tr| map.follows(tr)) {
                map.values(x)
            } else {
                let followed: Vec<Transform> = transforms.iter().filter(|tr| map.follows(tr)).cloned().collect();
                map.values(&self.transformed(&followed))
            };
        }
        terms
    }

    /// The recorded input through `transforms` and its kinematics, made once ([`super::fed`]).
    pub(super) fn fed(&self, transforms: &[Transform]) -> Option<std::sync::Arc<Fed>> {
        // Given rates make the kinematics whatever the estimator, once it can be built.
        let rates = match self.data.rates {
            Some(_) => {
                self.rate.build(self.data.dt as f32).ok()?;
                None
            }
            None => super::fed::rates(self.rate),
        };
        self.feeds.get_or_make(rates, transforms, || {
            let x = self.transformed(transforms);
            let kin = self.kin_of(&x)?;
            Some(Fed { x, kin })
        })
    }

    /// The base model's kinematics for the (transformed) input `x`.
    pub(super) fn kin_of(&self, x: &[f64]) -> Option<Vec<model_core::Kin>> {
        // Given rates are the zero-phase ones: recomputed for the transformed input.
        let (dt, u) = (self.data.dt as f32, self.data.command.as_deref());
        if self.data.rates.is_none() {
            return kinematics(&crate::models::replay::samples(x, u), dt, self.rate);
        }
        let (dx, ddx) = crate::numerics::derivative::rates_below(x, self.data.dt, self.rate_cutoff_hz);
        kinematics_given(x, u, &dx, &ddx, dt, self.rate)
    }

    pub(super) fn run_kin(&self, theta: &[f64], kin: &[model_core::Kin]) -> Option<Vec<f64>> {
        let mut out = vec![0.0; kin.len()];
        self.sim.run(theta, kin, &mut out).then_some(out)
    }

    /// Forward-difference columns `∂m/∂θ_j` for the free parameters.
    fn jacobian(&self, theta: &[f64], kin: &[model_core::Kin], m0: &[f64]) -> Vec<Vec<f64>> {
        self.spec
            .free()
            .par_iter()
            .filter_map(|&j| {
                let ps = self.spec.params.get(j)?;
                let v = *theta.get(j)?;
                let h = match ps.spacing {
                    Spacing::Linear => 1e-4 * (ps.hi - ps.lo),
                    Spacing::Log => 1e-3 * v.abs().max(ps.lo),
                };
                let h = if v + h > ps.hi { -h } else { h };
                let mut p = theta.to_vec();
                p[j] = v + h;
                let m = self.run_kin(&p, kin)?;
                Some(m.iter().zip(m0).map(|(a, b)| (a - b) / h).collect())
            })
            .collect()
    }

    /// The least squares of `terms` on the training rows, their additive columns prepared.
    fn projection(&self, terms: &[Term]) -> Projection {
        let fixed: Vec<Option<&[f64]>> = terms.iter().map(|t| t.is_additive().then_some(t.values.as_slice())).collect();
        Projection::new(&fixed, &self.train).at_least_zero(terms.iter().map(Term::at_least_zero).collect())
    }

    /// β for fixed θ (the model output `m`, which becomes the prediction): least squares of
    /// `y − m` on the terms' columns (`projection`: the terms' own), and the training MSE when
    /// `with_mse` (NaN otherwise).
    fn add_terms(
        &self,
        terms: &[Term],
        projection: &Projection,
        m: &mut [f64],
        with_mse: bool,
    ) -> Option<(Vec<f64>, f64)> {
        let cols: Vec<std::borrow::Cow<'_, [f64]>> = terms.iter().map(|t| t.column(m)).collect();
        let varying: Vec<&[f64]> =
            terms.iter().zip(&cols).filter(|(t, _)| !t.is_additive()).map(|(_, c)| &**c).collect();
        let (beta, mse) = if with_mse {
            projection.fit_for(&varying, &self.data.output, m)?
        } else {
            (projection.coefficients_for(&varying, &self.data.output, m)?, f64::NAN)
        };
        for (c, b) in cols.iter().zip(&beta) {
            for (p, v) in m.iter_mut().zip(c.iter()) {
                *p += b * v;
            }
        }
        Some((beta, mse))
    }

    /// Refit θ, β and the candidate's value of the model `transforms` + `terms` (+ what
    /// `tune` builds), from `theta` (and `tune.start`), by the fit's bounded
    /// Levenberg–Marquardt on its reduced step ([`crate::numerics::reduce`]: tens of
    /// thousands of rows, a handful of parameters) with at most `iterations` Jacobians. Returns the fit and the
    /// candidate's final value (0 without one); `None` when the start diverges.
    pub fn refit(
        &self,
        transforms: &[Transform],
        terms: &[Term],
        tune: Option<&Tune<'_>>,
        theta: &[f64],
        iterations: usize,
    ) -> Option<(Fitted, f64)> {
        let aug = AugSim { prob: self, transforms, terms, tune, cache: std::sync::Mutex::new(Vec::new()) };
        let p = self.solve(&aug, theta, iterations);
        let (m, beta, pred, mse, transforms, terms) = aug.full(&p)?;
        let g = p.get(self.sim.n_params()).copied().unwrap_or(0.0);
        let theta = p.get(..self.sim.n_params())?.to_vec();
        Some((Fitted { transforms, terms, theta, beta, model: m, pred, train_mse: mse }, g))
    }

    /// [`Problem::refit`] without a candidate's value, for its θ and training MSE only: the
    /// base model is run up to the last training row, not over the whole recording (a
    /// profile's refit on the first seconds of a long one). The same θ and MSE to the bit,
    /// but where the base model diverges only after the last training row: the whole refit
    /// fails there, this one does not.
    pub fn refit_train(
        &self,
        transforms: &[Transform],
        terms: &[Term],
        theta: &[f64],
        iterations: usize,
    ) -> Option<(Vec<f64>, f64)> {
        let aug = AugSim { prob: self, transforms, terms, tune: None, cache: std::sync::Mutex::new(Vec::new()) };
        let p = self.solve(&aug, theta, iterations);
        let mse = aug.train_mse(&p)?;
        Some((p, mse))
    }

    /// The parameters `aug`'s refit ends at (see [`Problem::refit`]).
    fn solve(&self, aug: &AugSim<'_, '_>, theta: &[f64], iterations: usize) -> Vec<f64> {
        let mut spec = self.spec.clone();
        // A fitted value outside the refits' box (a parameter held ≥ 0 after the fit) starts
        // inside it: from outside, the box's end would stick and the start win unchanged.
        let mut start: Vec<f64> =
            theta.iter().enumerate().map(|(j, v)| spec.params.get(j).map_or(*v, |p| p.into_box(*v))).collect();
        if let Some(t) = aug.tune {
            let (lo, hi) = (t.lo.min(t.hi), t.hi.max(t.lo));
            spec.params.push(crate::models::search::ParamSpec {
                name: "candidate",
                lo,
                hi,
                start: t.start.clamp(lo, hi),
                spacing: if t.log && lo > 0.0 { Spacing::Log } else { Spacing::Linear },
                fixed: false,
            });
            start.push(t.start.clamp(lo, hi));
        }
        if iterations == 0 {
            return start;
        }
        // AugSim makes its own kinematics (through the transforms): the objective's are
        // read only for their length.
        let kin = vec![model_core::Kin::default(); self.data.len()];
        let (y, train) = (&self.data.output, &self.train);
        let obj = crate::ident::fit::objective::Objective::new(aug, &spec, &kin, y, train, self.scale);
        let r = crate::ident::fit::lm::minimize_reduced(&obj, &start, iterations);
        if r.cost.is_finite() && r.cost <= obj.cost(&start) {
            r.params
        } else {
            start
        }
    }

    /// Training MSE of `transforms` + `terms` linearised about `theta`: the base model's
    /// Jacobian `jac` (taken at the current transforms) stands in for the refit of θ. One
    /// run of the base model, for scanning a candidate's grid cheaply.
    pub fn scan_cost(&self, transforms: &[Transform], terms: &[Term], theta: &[f64], jac: &[Vec<f64>]) -> Option<f64> {
        let fed = self.fed(transforms)?;
        let m = self.run_fed(theta, transforms, &fed)?;
        let terms = self.through(terms.to_vec(), transforms, &fed.x);
        let term_cols: Vec<std::borrow::Cow<'_, [f64]>> = terms.iter().map(|t| t.column(&m)).collect();
        let cols: Vec<&[f64]> = jac.iter().map(Vec::as_slice).chain(term_cols.iter().map(|c| &**c)).collect();
        let target: Vec<f64> = self.data.output.iter().zip(&m).map(|(y, m)| y - m).collect();
        projection::lsq(&cols, &target, &self.train).map(|(_, mse)| mse)
    }

    /// The base model's Jacobian at `theta` through `transforms`.
    pub fn jacobian_at(&self, theta: &[f64], transforms: &[Transform]) -> Option<Vec<Vec<f64>>> {
        let fed = self.fed(transforms)?;
        let m0 = self.run_fed(theta, transforms, &fed)?;
        Some(self.jacobian(theta, &fed.kin, &m0))
    }
}

#[cfg(test)]
mod tests;
