//! The firmware's per-sample control step and its parts, `no_std`, f32, no allocation.
//!
//! Signal path of [`step::ControlStep::step`], one call per ADC interrupt:
//! ADC counts → B and coil current ([`calibration`]) → rate and torque estimate
//! ([`Estimator`](crate::Estimator), any model) → torque PI with anti-windup ([`pi`]) plus the
//! feed-forward from the inverse of the model's static part ([`feedforward`]), at half the
//! sample rate in two phases on alternate samples → coil current PI, every sample →
//! H-bridge duty with the demagnetising pulse ([`pwm`]). The [`supervisor`] checks every
//! sample for what must act at once (Hall at a rail, over-current, supply outside its window,
//! overrun, model output non-finite) and latches a fault code; any fault ends in the safe
//! state (PWM off, bridge high-impedance so the coil de-energises through the diodes).
//! What need not run every sample runs in [`step::ControlStep::slow`] (about 1 kHz): the
//! configuration check, the time-step check, the temperature compensation, the
//! feed-forward's linearisation (operating point, static torque, slope), and the
//! slow-developing checks (Hall noise, stuck Hall, coil open,
//! B/i band), judged on the samples the step logged since the previous pass (their fault
//! latency: their sample count plus at most one slow period plus one sample); the
//! per-sample step trips if that pass stalls.
//! Settings are a [`config::ValidatedConfig`]: validated once, CRC-protected, swapped in
//! between samples by replacing a `Copy` value. The flash page that holds the model, its
//! parameters and these settings is [`page`]; [`physics`] checks a page's model on a slow
//! sweep of the field before the page is committed.

pub mod calibration;
pub mod config;
pub mod feedforward;
pub mod page;
pub mod physics;
pub mod pi;
pub mod pwm;
pub mod step;
pub mod supervisor;

pub use config::{ControlConfig, LoopMode, ValidatedConfig};
pub use page::{ConfigImage, PageError, RateSpec};
pub use physics::PhysicsFault;
pub use step::{ControlInput, ControlOutput, ControlState, ControlStep, Mode};
pub use supervisor::FaultCode;
