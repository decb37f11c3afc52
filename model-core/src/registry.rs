//! The list of every model: identifier, parameter names, `no_std` and state size.
//! `hil-sim models --json` prints exactly this.
//!
//! The model types are listed once, in [`for_each_model!`](crate::for_each_model); everything that needs the
//! list (this table, [`visit`], the host's per-model registry in `hil-sim`) is built from
//! it, so an 18th model is one line here plus its module.

use crate::Model;

/// Static description of one model.
#[derive(Clone, Copy, Debug)]
pub struct ModelInfo {
    pub id: &'static str,
    pub params: &'static [&'static str],
    pub n_params: usize,
    /// Size of the model's `State` in bytes (the registered size for const-generic ones).
    pub state_bytes: usize,
    /// Every model here is `no_std`; kept as a field because the contract prints it.
    pub no_std: bool,
    /// Where the equations come from.
    pub source: &'static str,
}

const fn info<M: Model>(source: &'static str) -> ModelInfo {
    ModelInfo {
        id: M::ID,
        params: M::PARAM_NAMES,
        n_params: M::N_PARAMS,
        state_bytes: core::mem::size_of::<M::State>(),
        no_std: true,
        source,
    }
}

/// Calls the macro `$callback` with every registered model type, in the order of the
/// contract, as a comma-separated list of `path => "where the equations come from"`: the
/// one list of models.
///
/// ```
/// macro_rules! count { ($($m:path => $src:literal),* $(,)?) => { [$(<$m as model_core::Model>::ID),*].len() } }
/// assert_eq!(model_core::for_each_model!(count), model_core::MODELS.len());
/// ```
#[macro_export]
macro_rules! for_each_model {
    ($callback:ident) => {
        $callback! {
            $crate::models::algebraic::Registered => "seed 000 eq. 14",
            $crate::models::bouc_wen::Registered => "seed 000 eq. 3-4; seeds 001/003 eq. 1-2 (general n, x0)",
            $crate::models::lugre::Registered => "seed 000 eq. 7-8; seed 001 mLF",
            $crate::models::tanh::Registered => "seed 000 eq. 11-12 (Kwok)",
            $crate::models::hammerstein_wiener::Registered => "seed 000 eq. 15-17",
            $crate::models::narx::Registered => "seed 000 eq. 18-19",
            $crate::models::bingham::Registered => "seed 003 (Bingham)",
            $crate::models::spencer::Registered => "seed 001 eq. 3-7 (modified Bouc-Wen, Spencer 1997)",
            $crate::models::dahl::Registered => "seed 001 eq. 8-11 (modified Dahl)",
            $crate::models::arctan::Registered => "seed 001 eq. 16 (Guo)",
            $crate::models::arctan_inertia::Registered => "seed 001 eq. 17 (modified algebraic, m*xdd)",
            $crate::models::trig::Registered => "seed 002 eq. 10-12, 31-37",
            $crate::models::preisach::Registered => "seed 004 eq. 5-9",
            $crate::models::prandtl_ishlinskii::Registered => "seed 004 eq. 10-15",
            $crate::models::gpi::Registered => "seed 004 eq. 16-22",
            $crate::models::maxwell_slip::Registered => "seed 004 eq. 23-25",
            $crate::models::bouc_wen_asym::Registered => "seed 004 eq. 29-31",
        }
    };
}

/// Something generic over the model type, applied by [`visit`] to the model an identifier
/// names.
pub trait Visit {
    type Out;
    fn visit<M: Model>(self) -> Self::Out;
}

macro_rules! visit_by_id {
    ($($m:path => $src:literal),* $(,)?) => {
        /// Apply `v` to the model type registered under `id`; `None` for an unknown id.
        ///
        /// ```
        /// use model_core::{registry::{visit, Visit}, Model};
        /// struct Params;
        /// impl Visit for Params {
        ///     type Out = usize;
        ///     fn visit<M: Model>(self) -> usize { M::N_PARAMS }
        /// }
        /// assert_eq!(visit("algebraic", Params), Some(4));
        /// assert_eq!(visit("nope", Params), None);
        /// ```
        pub fn visit<V: Visit>(id: &str, v: V) -> Option<V::Out> {
            $(if id == <$m as Model>::ID {
                return Some(v.visit::<$m>());
            })*
            None
        }
    };
}
for_each_model!(visit_by_id);

macro_rules! model_table {
    ($($m:path => $src:literal),* $(,)?) => {
        /// Every model, in the order of the contract.
        pub const MODELS: [ModelInfo; [$($src),*].len()] = [$(info::<$m>($src)),*];
    };
}
for_each_model!(model_table);

/// Look a model up by identifier.
pub fn find(id: &str) -> Option<&'static ModelInfo> {
    MODELS.iter().find(|m| m.id == id)
}
