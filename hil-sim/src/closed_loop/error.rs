//! Why a closed-loop run could not be set up.

use model_core::ParamError;
use thiserror::Error;

/// Why a loop run could not be set up.
#[derive(Debug, Error)]
pub enum LoopError {
    #[error("controller parameters: {0}")]
    Params(#[from] ParamError),
    #[error("{field} = {value}: {reason}")]
    Spec { field: &'static str, value: f64, reason: &'static str },
    #[error(transparent)]
    Limit(#[from] crate::sim::plant::limits::LimitError),
    #[error("identification failed: {0}")]
    Identify(String),
    /// [`evaluate`](super::evaluate) could not identify the clutch.
    #[error("identifying the simulated clutch")]
    Identifying(#[source] Box<LoopError>),
}
