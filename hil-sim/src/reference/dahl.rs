//! PLACEHOLDER — f64 reference to be written.
use super::Case;

/// Published parameter sets to check.
pub fn cases() -> Vec<Case> {
    Vec::new()
}
