//! What the concealed-effect generator is asked for ([`ConcealedSpec`]: effect, base model,
//! excitation, size, length) and why it can refuse ([`ConcealedError`]). The errors carry
//! the values; the CLI names its flags when it prints them.

use model_core::{models, Model};
use thiserror::Error;

/// Every effect `generate` can conceal (`none`: a null recording).
pub const EFFECTS: &[&str] = &[
    "none",
    "field_lag",
    "transport_delay",
    "saturation",
    "rate_dependence",
    "asymmetry",
    "thermal_drift",
    "slip_speed",
    "inertia",
    "aux_dependence",
    "sensor_offset",
];
/// Base models of the truth.
pub const BASES: &[&str] = &[
    models::algebraic::Registered::ID,
    models::bouc_wen::Registered::ID,
    models::lugre::Registered::ID,
    models::tanh::Registered::ID,
    models::dahl::Registered::ID,
];
/// Field excitations.
pub const EXCITATIONS: &[&str] = &["multisine", "noise", "sweep", "triangle", "bipolar"];
/// Largest effect size, fraction of the torque span.
pub const MAX_SIZE: f64 = 0.5;

/// What to generate.
#[derive(Clone, Debug, PartialEq)]
pub struct ConcealedSpec {
    pub effect: String,
    pub base: String,
    pub excitation: String,
    /// RMS of the effect's change to the torque, fraction of the torque's span.
    pub size: f64,
    pub seed: u64,
    pub duration_s: f64,
    pub fs_hz: f64,
}

impl Default for ConcealedSpec {
    fn default() -> Self {
        Self {
            effect: "none".into(),
            base: models::bouc_wen::Registered::ID.into(),
            excitation: "multisine".into(),
            size: 0.04,
            seed: 1,
            duration_s: 30.0,
            fs_hz: 2000.0,
        }
    }
}

#[derive(Debug, Error, PartialEq)]
pub enum ConcealedError {
    #[error("unknown effect `{0}` (one of: {list})", list = EFFECTS.join(", "))]
    Effect(String),
    #[error("unknown base model `{0}` (one of: {list})", list = BASES.join(", "))]
    Base(String),
    #[error("unknown excitation `{0}` (one of: {list})", list = EXCITATIONS.join(", "))]
    Excitation(String),
    /// The size is outside `0..=MAX_SIZE`.
    #[error("size {0}: must be between 0 and 0.5 (a fraction of the torque span)")]
    Size(f64),
    /// Duration (s) and sampling rate (Hz) too short, too slow or too many samples.
    #[error("duration {0} s at {1} Hz: need at least 2 s and 200 Hz, at most 10^7 samples")]
    Length(f64, f64),
    #[error("the base model `{0}` diverged on this excitation")]
    Diverged(String),
    #[error(
        "`{effect}` cannot reach size {size} on base `{base}`: at most {reached:.4} of the torque span \
         (e.g. an input offset only shifts the output of a model linear in its input)"
    )]
    Unobservable { effect: String, base: String, size: f64, reached: f64 },
}
