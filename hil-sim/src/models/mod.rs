//! What each model needs on the host, reached by identifier through model-core's
//! registry ([`visit`]): running it over samples ([`replay()`]), its search box and start
//! values for identification, its f64 reference, the accuracy check of the f32 core.

pub mod accuracy;
pub mod reference;
pub mod replay;
pub mod search;

mod algebraic;
mod arctan;
mod arctan_inertia;
mod bingham;
mod bouc_wen;
mod bouc_wen_asym;
mod dahl;
mod gpi;
mod hammerstein_wiener;
mod lugre;
mod maxwell_slip;
mod narx;
mod prandtl_ishlinskii;
mod preisach;
mod spencer;
mod tanh;
mod trig;

use model_core::rate::RateParams;
use model_core::{Estimator, Model, ParamError, Sample};
use thiserror::Error;

pub use model_core::registry::{visit, Visit};

use model_core::Kin;
use search::{ModelSpec, ParamSpec, Scales, Strategy, Structure};

/// Most regressors a model linear in its parameters has.
pub const MAX_REGRESSORS: usize = 10;

/// What the host knows about one model type: implemented once per model, in
/// `models/<id>.rs`. A model-core model without an implementation does not compile
/// (the table [`HOSTS`] is built from model-core's `for_each_model!`).
pub trait HostModel: Model {
    /// The search box, start values and fitting method for data with these spreads: the
    /// papers' boxes written in the recording's own scales. `None` when the box cannot be
    /// built.
    fn search(s: &Scales) -> Option<(Vec<ParamSpec>, Strategy)>;

    /// The model-specific structure the fitting method exploits.
    const STRUCTURE: Structure = Structure::Generic;

    /// Variant `k ≥ 1` of the search (another value of a discrete parameter); the fit tries
    /// every variant and keeps the one with the lowest training cost. `None` past the last.
    fn variant(_sp: &ModelSpec, _k: usize, _s: &Scales) -> Option<ModelSpec> {
        None
    }

    /// The regressor row at one sample for a model linear in its parameters: writes them
    /// into `row` and returns how many there are; `None` for a model that is not linear.
    fn regressors(_k: &Kin, _row: &mut [f64; MAX_REGRESSORS]) -> Option<usize> {
        None
    }

    /// Published parameter sets checked against an independent f64 reference
    /// (`hil-sim accuracy`); empty for a model without an ODE.
    fn reference_cases() -> Vec<reference::Case> {
        Vec::new()
    }
}

/// One model's host entry: [`HostModel`]'s functions as pointers, reachable by id.
#[derive(Clone, Copy)]
pub struct Host {
    pub id: &'static str,
    pub structure: Structure,
    search: fn(&Scales) -> Option<(Vec<ParamSpec>, Strategy)>,
    variant: fn(&ModelSpec, usize, &Scales) -> Option<ModelSpec>,
    regressors: fn(&Kin, &mut [f64; MAX_REGRESSORS]) -> Option<usize>,
    reference_cases: fn() -> Vec<reference::Case>,
}

impl Host {
    const fn of<M: HostModel>() -> Self {
        Self {
            id: M::ID,
            structure: M::STRUCTURE,
            search: M::search,
            variant: M::variant,
            regressors: M::regressors,
            reference_cases: M::reference_cases,
        }
    }

    /// The search specification for data with these scales; `rate` overrides the default
    /// rate estimator ([`search::default_rate`]).
    pub fn spec(&self, s: &Scales, rate: Option<RateChoice>) -> Option<ModelSpec> {
        let (params, strategy) = (self.search)(s)?;
        let rate = rate.unwrap_or_else(|| search::default_rate(s));
        Some(ModelSpec { id: self.id, params, strategy, structure: self.structure, rate })
    }

    /// Variant `k ≥ 1` of a search, see [`HostModel::variant`].
    pub fn variant(&self, sp: &ModelSpec, k: usize, s: &Scales) -> Option<ModelSpec> {
        (self.variant)(sp, k, s)
    }

    /// The regressor row at one sample (`None` for a model that is not linear).
    pub fn regressors(&self, k: &Kin) -> Option<Vec<f64>> {
        let mut row = [0.0; MAX_REGRESSORS];
        let n = self.regressors_into(k, &mut row)?;
        Some(row.get(..n)?.to_vec())
    }

    /// [`Host::regressors`] into a fixed row, without allocating; returns how many.
    pub fn regressors_into(&self, k: &Kin, row: &mut [f64; MAX_REGRESSORS]) -> Option<usize> {
        (self.regressors)(k, row)
    }

    /// Published sets with their f64 references.
    pub fn reference_cases(&self) -> Vec<reference::Case> {
        (self.reference_cases)()
    }
}

macro_rules! host_table {
    ($($m:path => $src:literal),* $(,)?) => {
        /// Every model's host entry, in model-core's registry order.
        pub static HOSTS: [Host; [$($src),*].len()] = [$(Host::of::<$m>()),*];
    };
}
model_core::for_each_model!(host_table);

/// The host entry of model `id`; `None` for an unknown id.
pub fn host(id: &str) -> Option<&'static Host> {
    HOSTS.iter().find(|h| h.id == id)
}

/// Which rate estimator a replay uses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RateChoice {
    Backward,
    /// First-order filtered differentiator, cutoff in Hz.
    Filtered(f32),
    /// Seed 002's Kalman filter with jerk intensity `q` and measurement variance `r`.
    Kalman {
        q: f32,
        r: f32,
    },
}

impl RateChoice {
    /// `backward`, `filtered:FC_HZ`, `kalman` (seed 002's q = 200, r = 0.01) or `kalman:Q:R`.
    pub fn parse(s: &str) -> Result<Self, String> {
        let parts: Vec<&str> = s.split(':').collect();
        let num = |p: &str| p.parse::<f32>().map_err(|_| format!("--rate {s}: `{p}` is not a number"));
        Ok(match parts.as_slice() {
            ["backward"] => Self::Backward,
            ["filtered", fc] => Self::Filtered(num(fc)?),
            ["kalman"] => Self::Kalman { q: 200.0, r: 0.01 },
            ["kalman", q, r] => Self::Kalman { q: num(q)?, r: num(r)? },
            _ => return Err(format!("--rate {s}: expected backward, filtered:FC_HZ or kalman[:Q:R]")),
        })
    }

    /// The form the firmware's configuration page stores.
    pub fn spec(self) -> model_core::control::RateSpec {
        use model_core::control::RateSpec;
        match self {
            Self::Backward => RateSpec::Backward,
            Self::Filtered(fc) => RateSpec::Filtered { fc },
            Self::Kalman { q, r } => RateSpec::Kalman { q, r },
        }
    }

    pub fn build(self, dt: f32) -> Result<RateParams, ParamError> {
        match self {
            Self::Backward => RateParams::backward(dt),
            Self::Filtered(fc) => RateParams::filtered(dt, fc),
            Self::Kalman { q, r } => RateParams::kalman(dt, q, r),
        }
    }
}

/// Why a replay could not start.
#[derive(Debug, Error)]
pub enum ReplayError {
    #[error("unknown model `{0}` (see `hil-sim models`)")]
    UnknownModel(String),
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

struct Run<'a> {
    params: &'a [f32],
    dt: f32,
    rate: RateChoice,
    samples: &'a [Sample],
}

impl Visit for Run<'_> {
    type Out = Result<Replay, ParamError>;
    fn visit<M: Model>(self) -> Self::Out {
        let model = M::from_params(self.params, self.dt)?;
        let est = Estimator::new(model, self.rate.build(self.dt)?)?;
        let mut st = est.state();
        let mut out = Replay { y: Vec::with_capacity(self.samples.len()), held: 0 };
        for s in self.samples {
            let o = est.step(&mut st, *s);
            out.held += usize::from(!o.flags.ok());
            out.y.push(o.y);
        }
        Ok(out)
    }
}

/// Run `samples` through model `id` with flat parameters `params`, one step per sample
/// of `dt` seconds, in f32 — the code the firmware runs.
pub fn replay(id: &str, params: &[f32], dt: f32, rate: RateChoice, samples: &[Sample]) -> Result<Replay, ReplayError> {
    visit(id, Run { params, dt, rate, samples })
        .ok_or_else(|| ReplayError::UnknownModel(id.to_owned()))?
        .map_err(|source| ReplayError::Params { model: id.to_owned(), source })
}

#[cfg(test)]
mod tests;

#[cfg(test)]
mod replay_tests {
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
        let r = replay("algebraic", &[2.0, 0.0, 0.0, 1.0], 0.01, RateChoice::Backward, &s).unwrap();
        assert_eq!(r.y, vec![1.0, 3.0, 5.0, 7.0]);
        assert!(matches!(replay("nope", &[], 0.01, RateChoice::Backward, &s), Err(ReplayError::UnknownModel(_))));
        let e = replay("algebraic", &[1.0], 0.01, RateChoice::Backward, &s).unwrap_err();
        assert!(e.to_string().contains("expected 4 parameters"), "{e}");
    }
}
