//! Why a closed-loop run could not be set up.

use model_core::ParamError;
use thiserror::Error;

/// Why a loop run could not be set up.
#[derive(Debug, Error)]
pub enum LoopError {
    #[error("controller parameters: {0}")]
    Params(#[from] ParamError),
    #[error("{field} = {}: {reason}", crate::numerics::shown(*value))]
    Spec { field: &'static str, value: f64, reason: &'static str },
    #[error(transparent)]
    Limit(#[from] crate::sim::plant::limits::LimitError),
    #[error("{name}: the recording has no row ({duration_s} s at {record_hz} Hz)")]
    EmptyRecording { name: String, duration_s: f64, record_hz: f64 },
    #[error("{name}: column `{column}` row {row} is {} (the simulation diverged); nothing written", crate::numerics::shown(*value))]
    NonFinite { name: String, column: String, row: usize, value: f64 },
    #[error("identification failed: {0}")]
    Identify(String),
    /// [`evaluate`](super::evaluate) could not identify the clutch.
    #[error("identifying the simulated clutch")]
    Identifying(#[source] Box<LoopError>),
}
