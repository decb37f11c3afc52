//! The firmware's control step ([`model_core::control`]) against the simulated clutch.
//!
//! Per sample of `1/control_hz` s: the plant's ADCs are sampled (12-bit Hall and current
//! counts, supply voltage, temperature), the control step computes the new duty (PWM
//! quantised to the timer's compare counts), and that duty is applied from the **next**
//! sample on (one-sample computation delay); between samples the plant integrates every
//! PWM edge ([`crate::sim::plant`]). The true torque is the plant's.
//! The slow supervisor pass (`ControlStep::slow`) runs every millisecond, as in the firmware.
//!
//! [`identify`](fn@identify) plays the lab: on the simulated clutch, with the same step in current
//! mode as the current driver, it records sines and a slow triangle, fits seed 000's
//! algebraic model (eq. 14, linear least squares on Hall B, its rate from the
//! controller's own rate estimator, and the load-cell torque) for the closed loop, and the
//! static current → torque map for the **baseline** (open-loop current control, what a
//! user without B sensing has).
//!
//! Modules: [`harness`] (one run, sample by sample), [`injection`] (faults and how they
//! enter the plant), [`tuning`] (settings from the data sheet and the identified slope),
//! [`identify`](mod@identify) (the lab's fits, by [`crate::numerics::lstsq::fit_rows`]),
//! [`faults`] (one injected fault, judged), [`frequency_response`](mod@frequency_response)
//! (stepped sines, −3 dB bandwidth), [`step_response`] (10–90 % rise times), [`heating`]
//! (error drift as the fluid heats), [`references`] (the scenarios' torque references),
//! [`record`] (a current-driven scenario recorded, `hil-sim simulate`), [`scenarios`] (the `loop` scenarios as one call), [`error`] (why a run could not be set up).

pub mod error;
pub mod faults;
pub mod frequency_response;
pub mod harness;
pub mod heating;
pub mod identify;
pub mod injection;
pub mod record;
pub mod references;
pub mod replay;
pub mod rig;
pub mod scenarios;
pub mod step_response;
pub mod tuning;

pub use error::LoopError;
pub use faults::{fault_run, is_fault, FaultResult};
pub use frequency_response::{bandwidth, frequency_response, GainPoint, SWEEP_HZ};
pub use harness::{run, Run, T_START};
pub use heating::{heating_windows, HeatingWindow, WindowError};
pub use identify::{identify, Identified};
pub use injection::{Injection, NanAfter, NanState, Schedule};
pub use references::multisine_reference;
pub use scenarios::{compare, evaluate, LoopReport, LoopScenario, LoopSpec, ScenarioFigures};
pub use step_response::{rise_time, step_rises, StepRise};
pub use tuning::{base_config, current_driver, RATE_FC_HZ};
