//! Pieces shared by several models, one idea per file. A model module uses kernels, never
//! another model module.
//!
//! - [`turning`]: the input's reversal inside a step (`bouc_wen`, `lugre`);
//! - [`command_filter`]: the first-order command filter of eq. 7 of Spencer et al. (1997) and the
//!   unipolar command (`spencer`, `dahl`);
//! - [`operators`]: operator counts and flat-vector plumbing (`prandtl_ishlinskii`, `gpi`,
//!   `maxwell_slip`);
//! - [`names`]: compile-time `name[N]` parameter names (operator, network and NARX models);
//! - [`flat`]: validated blocks read out of a flat parameter vector (`hammerstein_wiener`, `narx`);
//! - [`sigmoid`]: the logistic unit and weight bound (`hammerstein_wiener`, `narx`);
//! - [`poly`]: polynomials in the command (`bingham`, `trig`);
//! - [`arctan_law`]: the arctan force law of seed 001 eq. 16 (`arctan`, `arctan_inertia`).

pub(crate) mod arctan_law;
pub(crate) mod command_filter;
pub(crate) mod flat;
pub(crate) mod names;
pub(crate) mod operators;
pub(crate) mod poly;
pub(crate) mod sigmoid;
pub(crate) mod turning;
