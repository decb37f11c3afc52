//! What a diagnosis is asked to do ([`DiagnoseOptions`]) and why it can fail
//! ([`DiagnoseError`]). Plain values: the CLI and the demo both build them, and the CLI
//! names its flags when it prints an error.

use thiserror::Error;

use crate::ident::fit::FitError;
use crate::models::RateSpec;

/// Smallest and largest fraction of the recording a diagnosis may hold out.
pub const HELDOUT_RANGE: std::ops::RangeInclusive<f64> = 0.05..=0.8;

/// Why a diagnosis could not run.
#[derive(Debug, Error)]
pub enum DiagnoseError {
    #[error(transparent)]
    Fit(#[from] FitError),
    /// The held-out fraction is outside [`HELDOUT_RANGE`].
    #[error("held-out fraction {0}: must be between 0.05 and 0.8")]
    Heldout(f64),
    #[error("no base model could be fitted: {0}")]
    NoBase(String),
    #[error("the base model `{0}` cannot be refitted by the diagnosis (not a parametric model)")]
    NotParametric(String),
    #[error("the fitted base model `{0}` diverges when replayed")]
    Diverges(String),
}

/// How to diagnose.
#[derive(Clone, Debug)]
pub struct DiagnoseOptions {
    /// Base model id; `None` for `auto`.
    pub model: Option<String>,
    /// Fraction of the recording held out (the end of it).
    pub heldout: f64,
    /// Rate estimator of the models; `None`: the zero-phase offline rate
    /// ([`crate::numerics::derivative`]), so that no estimator lag is mistaken for the clutch's.
    pub rate: Option<RateSpec>,
    pub seed: u64,
    /// Rounds of naming and modelling.
    pub max_findings: usize,
    /// Sample indices where one run of a multi-run recording ends and the next begins; a
    /// finding whose windows sit on them says so.
    pub boundaries: Vec<usize>,
}

impl Default for DiagnoseOptions {
    fn default() -> Self {
        Self { model: None, heldout: 0.3, rate: None, seed: 1, max_findings: 3, boundaries: Vec::new() }
    }
}

impl DiagnoseOptions {
    /// Whether the options make sense before any data is read (the held-out fraction).
    pub fn check(&self) -> Result<(), DiagnoseError> {
        if HELDOUT_RANGE.contains(&self.heldout) {
            Ok(())
        } else {
            Err(DiagnoseError::Heldout(self.heldout))
        }
    }
}
