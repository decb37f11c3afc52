//! The logistic sigmoid unit of the sigmoid networks (MATLAB's `sigmoidnet`) of
//! [`hammerstein_wiener`](super::super::hammerstein_wiener) and [`narx`](super::super::narx),
//! and the bound on their weights.

use crate::math::exp;

/// Largest admissible magnitude of any weight.
pub const W_MAX: f32 = 1.0e6;

/// Logistic sigmoid `1/(1 + e^{−s})`, total (0 at −∞, 1 at +∞). Shared with `narx`.
#[inline]
pub(crate) fn sigmoid(s: f32) -> f32 {
    1.0 / (1.0 + exp(-s))
}
