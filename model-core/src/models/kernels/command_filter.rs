//! The first-order command filter of Spencer et al. (1997) eq. 7 (seed 001 eq. 11),
//! `u̇ = −η·(u − max(v, 0))`, advanced exactly between samples, and the unipolar command
//! it is driven by. Shared by the MR damper models [`spencer`](super::super::spencer) and
//! [`dahl`](super::super::dahl).

use crate::math::{exp, expm1};

/// Eq. 7 (and seed 001 eq. 11), `u̇ = −η(u − max(v, 0))`, advanced exactly over one step
/// for a raw command `v` linear between samples and clamped at 0 V (a step whose command
/// crosses 0 V is split at the crossing).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CommandFilter {
    /// `ηT`
    pub eta_t: f32,
    /// `e^{−ηT}`
    pub decay: f32,
    /// `(1 − e^{−ηT})/(ηT)`
    pub ramp: f32,
}

/// `(e^{−x}, (1 − e^{−x})/x)` without cancellation for small x.
#[inline]
fn decay_ramp(x: f32) -> (f32, f32) {
    let ramp = if x < 1e-3 { 1.0 - 0.5 * x + x * x / 6.0 } else { -expm1(-x) / x };
    (exp(-x), ramp)
}

impl CommandFilter {
    /// Filter rate `eta` (s⁻¹, > 0) at step `dt`.
    pub fn new(eta: f32, dt: f32) -> Self {
        let eta_t = eta * dt;
        let (decay, ramp) = decay_ramp(eta_t);
        Self { eta_t, decay, ramp }
    }

    /// The filtered command after one step from `u0` when the raw command moved linearly
    /// from `v0` to `v1` over the step (negative parts count as 0 V). Never negative.
    #[inline]
    pub fn step(&self, u0: f32, v0: f32, v1: f32) -> f32 {
        let foh = |u0: f32, a: f32, b: f32, (decay, ramp): (f32, f32)| b + (u0 - a) * decay - (b - a) * ramp;
        let u1 = if v0 >= 0.0 && v1 >= 0.0 {
            foh(u0, v0, v1, (self.decay, self.ramp))
        } else if v0 <= 0.0 && v1 <= 0.0 {
            u0 * self.decay
        } else {
            // The command crosses 0 V at the fraction `tc` of the step.
            let tc = v0 / (v0 - v1);
            if v0 < 0.0 {
                let u_mid = u0 * exp(-self.eta_t * tc);
                foh(u_mid, 0.0, v1, decay_ramp(self.eta_t * (1.0 - tc)))
            } else {
                foh(u0, v0, 0.0, decay_ramp(self.eta_t * tc)) * exp(-self.eta_t * (1.0 - tc))
            }
        };
        u1.max(0.0)
    }
}

/// The unipolar command: negative (and NaN) commands are 0 V.
#[inline]
pub fn command(u: f32) -> f32 {
    if u > 0.0 {
        u
    } else {
        0.0
    }
}

/// The raw command with NaN mapped to 0 (kept for the next step's interpolation).
#[inline]
pub fn raw_command(u: f32) -> f32 {
    if u.is_nan() {
        0.0
    } else {
        u
    }
}
