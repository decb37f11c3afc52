//! Reversals of the input inside one sample step, shared by [`bouc_wen`](super::super::bouc_wen)
//! and [`lugre`](super::super::lugre): with the rate `ẋ` and acceleration `ẍ` at the end of the
//! step, the input's extremum lies `τ = ẋ/ẍ` before the sample (if `0 < τ < dt`) at
//! `x_t = x − ẋ·τ/2`.

use crate::math::sign;
use crate::Kin;

/// Largest `α·|B̈|·dt²` (the z change a reversal inside the step could make) for which the
/// short-step path ignores the reversal.
pub(crate) const TURN_EPS: f32 = 2.0e-3;

/// The input's extremum inside the step `(t_{k−1}, t_k]`, if `k.dx`, `k.ddx` place one there
/// and it lies beyond both `x_prev` and `k.x` (see the module doc). Shared by `bouc_wen` and `lugre`.
#[inline]
pub(crate) fn turning_point(x_prev: f32, k: &Kin, dt: f32) -> Option<f32> {
    let (dx, ddx) = (k.dx, k.ddx);
    if !(dx != 0.0 && ddx != 0.0) {
        return None;
    }
    let tau = dx / ddx;
    if !(tau > 0.0 && tau < dt) {
        return None;
    }
    let xt = k.x - 0.5 * dx * tau;
    let s = sign(dx);
    if (x_prev - xt) * s > 0.0 && (k.x - xt) * s > 0.0 && xt.is_finite() {
        Some(xt)
    } else {
        None
    }
}
