//! The list of every model: identifier, parameter names, `no_std` and state size.
//! `hil-sim models --json` prints exactly this.

use crate::models;
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

/// Every model, in the order of the contract.
pub const MODELS: [ModelInfo; 17] = [
    info::<models::algebraic::Registered>("seed 000 eq. 14"),
    info::<models::bouc_wen::Registered>("seed 000 eq. 3-4; seeds 001/003 eq. 1-2 (general n, x0)"),
    info::<models::lugre::Registered>("seed 000 eq. 7-8; seed 001 mLF"),
    info::<models::tanh::Registered>("seed 000 eq. 11-12 (Kwok)"),
    info::<models::hammerstein_wiener::Registered>("seed 000 eq. 15-17"),
    info::<models::narx::Registered>("seed 000 eq. 18-19"),
    info::<models::bingham::Registered>("seed 003 (Bingham)"),
    info::<models::spencer::Registered>("seed 001 eq. 3-7 (modified Bouc-Wen, Spencer 1997)"),
    info::<models::dahl::Registered>("seed 001 eq. 8-11 (modified Dahl)"),
    info::<models::arctan::Registered>("seed 001 eq. 16 (Guo)"),
    info::<models::arctan_inertia::Registered>("seed 001 eq. 17 (modified algebraic, m*xdd)"),
    info::<models::trig::Registered>("seed 002 eq. 10-12, 31-37"),
    info::<models::preisach::Registered>("seed 004 eq. 5-9"),
    info::<models::prandtl_ishlinskii::Registered>("seed 004 eq. 10-15"),
    info::<models::gpi::Registered>("seed 004 eq. 16-22"),
    info::<models::maxwell_slip::Registered>("seed 004 eq. 23-25"),
    info::<models::bouc_wen_asym::Registered>("seed 004 eq. 29-31"),
];

/// Look a model up by identifier.
pub fn find(id: &str) -> Option<&'static ModelInfo> {
    MODELS.iter().find(|m| m.id == id)
}
