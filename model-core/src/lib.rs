//! Hysteresis models of MR clutches and dampers as `no_std`, allocation-free, f32,
//! fixed-step processors — the exact code that runs on the STM32G474 and in `hil-sim`.
//!
//! Shape (after quartiq's idsp): every model has immutable, validated coefficients
//! ([`Model`] implementors, built by a fallible `new`/[`Model::from_params`]) and a
//! separate plain-`Copy` state. The hot path `model.step(&mut state, &kin)` cannot fail.
//!
//! The usual entry point is [`Estimator`]: it takes raw [`Sample`]s (input, optional
//! measured rate, optional auxiliary command), estimates the input's rate with a
//! selectable [`rate`] estimator, steps the model and guards the output against
//! non-finite values (see [`Estimator::step`] for the exact rule).
#![cfg_attr(not(test), no_std)]

pub mod control;
pub mod error;
pub mod estimator;
pub mod kinematics;
pub mod math;
pub mod model;
pub mod models;
pub mod protocol;
pub mod rate;
pub mod registry;

pub use error::ParamError;
pub use estimator::{Estimator, EstimatorState, Flags, Output};
pub use kinematics::{Kin, Sample};
pub use model::{Finite, Model};
pub use registry::{ModelInfo, MODELS};
