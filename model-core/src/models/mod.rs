//! One module per model, named by its identifier in `shared/spec/cli-contract.md`.
//!
//! Every module exports its coefficient type (implementing [`Model`](crate::Model)),
//! its `State`, and `pub type Registered = …;` — the concrete type (for const-generic
//! models, the default size) listed by [`registry`](crate::registry).
//!
//! Pieces several models share (the command filter, reversal detection, name tables, …)
//! live in `kernels` (crate-private); a model module uses kernels, never another model.

// Shared pieces (no model module uses another).
pub(crate) mod kernels;

// Seed 000 (Yang & Kermani 2023), input B.
pub mod algebraic;
pub mod bouc_wen;
pub mod hammerstein_wiener;
pub mod lugre;
pub mod narx;
pub mod tanh;
// Seeds 001 / 003 (MR dampers), input x.
pub mod arctan;
pub mod arctan_inertia;
pub mod bingham;
pub mod dahl;
pub mod spencer;
// Seed 002.
pub mod trig;
// Seed 004 (operator models).
pub mod bouc_wen_asym;
pub mod gpi;
pub mod maxwell_slip;
pub mod prandtl_ishlinskii;
pub mod preisach;
