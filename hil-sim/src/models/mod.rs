//! What each model needs on the host, reached by identifier through model-core's
//! registry ([`visit`]): running it over samples ([`replay()`]), its search box and start
//! values for identification, its f64 reference, the accuracy check of the f32 core.

pub mod alignment;
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

pub use model_core::registry::{visit, Visit};

use model_core::{Kin, Model};
use search::{ModelSpec, Scales, SearchBox, Structure};

/// Most regressors a model linear in its parameters has.
pub const MAX_REGRESSORS: usize = 10;

/// What the host knows about one model type: implemented once per model, in
/// `models/<id>.rs`. A model-core model without an implementation does not compile
/// (the table [`HOSTS`] is built from model-core's `for_each_model!`).
pub trait HostModel: Model {
    /// The search box, start values and fitting method for data with these spreads: the
    /// papers' boxes written in the recording's own scales. `None` when the box cannot be
    /// built.
    fn search(s: &Scales) -> Option<SearchBox>;

    /// The model-specific structure the fitting method exploits.
    const STRUCTURE: Structure = Structure::Generic;

    /// Parameters the output is affine in, jointly, once the others are fixed (tanh: `α, c,
    /// k, T₀`): the global search also starts from a grid over the others with these solved
    /// by least squares ([`crate::ident::fit::separable`]). Empty: none.
    const AFFINE: &'static [&'static str] = &[];

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
    /// [`HostModel::AFFINE`].
    pub affine: &'static [&'static str],
    search: fn(&Scales) -> Option<SearchBox>,
    variant: fn(&ModelSpec, usize, &Scales) -> Option<ModelSpec>,
    regressors: fn(&Kin, &mut [f64; MAX_REGRESSORS]) -> Option<usize>,
    reference_cases: fn() -> Vec<reference::Case>,
}

impl Host {
    const fn of<M: HostModel>() -> Self {
        Self {
            id: M::ID,
            structure: M::STRUCTURE,
            affine: M::AFFINE,
            search: M::search,
            variant: M::variant,
            regressors: M::regressors,
            reference_cases: M::reference_cases,
        }
    }

    /// The search specification for data with these scales; `rate` overrides the default
    /// rate estimator ([`search::default_rate`]).
    pub fn spec(&self, s: &Scales, rate: Option<RateSpec>) -> Option<ModelSpec> {
        let (params, strategy) = (self.search)(s)?;
        let rate = rate.unwrap_or_else(|| search::default_rate(s));
        Some(ModelSpec { id: self.id, params, strategy, structure: self.structure, rate })
    }

    /// Variant `k ≥ 1` of a search, see [`HostModel::variant`].
    pub fn variant(&self, sp: &ModelSpec, k: usize, s: &Scales) -> Option<ModelSpec> {
        (self.variant)(sp, k, s)
    }

    /// The search `sp` as its variant `k`: `sp` itself for `k = 0`, else [`Host::variant`].
    pub fn at_variant(&self, sp: &ModelSpec, k: usize, s: &Scales) -> Option<ModelSpec> {
        if k == 0 {
            Some(sp.clone())
        } else {
            self.variant(sp, k, s)
        }
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

pub use model_core::control::RateSpec;
pub use replay::{replay, Replay, ReplayError};

#[cfg(test)]
mod tests;
