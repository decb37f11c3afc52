//! Rate estimators: the input's first and second time derivatives from sampled values.
//!
//! Three choices, selected by [`RateParams`]:
//! - [`RateParams::Backward`]: backward differences, seed 002 eq. 13–14
//!   (`ẋ_k = (x_k − x_{k−1})/T`, `ẍ_k = (x_k − 2x_{k−1} + x_{k−2})/T²`).
//! - [`RateParams::Filtered`]: backward difference followed by a first-order low-pass
//!   with cutoff `fc` (an exact discretisation, `a = exp(−2π·fc·T)`), the usual
//!   "dirty derivative"; the second derivative is the filtered difference of the first.
//! - [`RateParams::Kalman`]: the constant-acceleration Kalman filter of seed 002
//!   eq. 19–27 (state `[x, ẋ, ẍ]`, white jerk of intensity `q`, eq. 21, measurement noise
//!   variance `r`, eq. 20). The gain is the steady-state gain, obtained once in
//!   [`RateParams::kalman`] by iterating eq. 24, 25 and 27 to convergence, so the step is
//!   a fixed 3×3 update with no division. Seed 002's rate-dependent `R = 0.1²/(1+ẋ)`
//!   (eq. 22) is not used: it turns negative for ẋ < −1 and would make the gain vary per
//!   sample; a constant `r` is the documented choice here.

use crate::error::{check, time_step};
use crate::math::exp;
use crate::ParamError;

/// Validated estimator coefficients for one time step (`Filtered`: `a` the pole, `g = 1 − a`
/// the gain, stored so that a sample needs no subtraction).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RateParams {
    Backward { inv_dt: f32 },
    Filtered { inv_dt: f32, a: f32, g: f32 },
    Kalman { dt: f32, gain: [f32; 3] },
}

/// Estimator state (previous samples or the filter estimate).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RateState {
    /// Previous input sample (Backward/Filtered) or estimated `x` (Kalman).
    pub x: f32,
    /// Previous first derivative estimate.
    pub dx: f32,
    /// Previous second derivative estimate.
    pub ddx: f32,
    /// Number of samples seen, saturating at 2.
    pub primed: u8,
}

impl crate::Finite for RateState {
    fn is_finite(&self) -> bool {
        self.x.is_finite() && self.dx.is_finite() && self.ddx.is_finite()
    }
}

impl RateParams {
    /// Backward differences at time step `dt` seconds.
    pub fn backward(dt: f32) -> Result<Self, ParamError> {
        let dt = time_step(dt)?;
        Ok(Self::Backward { inv_dt: 1.0 / dt })
    }

    /// Backward difference low-passed at `fc` Hz (0 < fc < Nyquist).
    pub fn filtered(dt: f32, fc: f32) -> Result<Self, ParamError> {
        let dt = time_step(dt)?;
        let fc = check("fc", fc, f32::MIN_POSITIVE, 0.5 / dt)?;
        let a = exp(-2.0 * core::f32::consts::PI * fc * dt);
        Ok(Self::Filtered { inv_dt: 1.0 / dt, a, g: 1.0 - a })
    }

    /// Steady-state constant-acceleration Kalman filter (seed 002 eq. 19–27) with jerk
    /// intensity `q` (seed 002 uses 200, in input units²/s⁵) and measurement variance `r`
    /// (seed 002 uses 0.1², input units²).
    pub fn kalman(dt: f32, q: f32, r: f32) -> Result<Self, ParamError> {
        let dt = time_step(dt)?;
        let q = check("q", q, f32::MIN_POSITIVE, f32::MAX)?;
        let r = check("r", r, f32::MIN_POSITIVE, f32::MAX)?;
        let gain = steady_state_gain(f64::from(dt), f64::from(q), f64::from(r))
            .ok_or(ParamError::Constraint { what: "Kalman gain did not converge (q/r out of range)" })?;
        Ok(Self::Kalman { dt, gain })
    }

    /// Estimate `(ẋ, ẍ)` for the new sample `x` and advance the state. The first sample
    /// gives zero rates; the second gives a first difference and zero acceleration.
    #[inline]
    pub fn step(&self, s: &mut RateState, x: f32) -> (f32, f32) {
        if s.primed == 0 {
            *s = RateState { x, dx: 0.0, ddx: 0.0, primed: 1 };
            return (0.0, 0.0);
        }
        match *self {
            Self::Backward { inv_dt } => {
                let dx = (x - s.x) * inv_dt;
                let ddx = if s.primed >= 2 { (dx - s.dx) * inv_dt } else { 0.0 };
                *s = RateState { x, dx, ddx, primed: 2 };
                (dx, ddx)
            }
            Self::Filtered { inv_dt, a, g } => {
                let raw = (x - s.x) * inv_dt;
                let dx = if s.primed >= 2 { a * s.dx + g * raw } else { raw };
                let raw2 = if s.primed >= 2 { (dx - s.dx) * inv_dt } else { 0.0 };
                let ddx = a * s.ddx + g * raw2;
                *s = RateState { x, dx, ddx, primed: 2 };
                (dx, ddx)
            }
            Self::Kalman { dt, gain } => {
                // Prediction, eq. 23 with A of eq. 19 and no input.
                let h = 0.5 * dt * dt;
                let px = s.x + dt * s.dx + h * s.ddx;
                let pdx = s.dx + dt * s.ddx;
                let pddx = s.ddx;
                // Update, eq. 26 with the steady-state gain.
                let innov = x - px;
                let [k0, k1, k2] = gain;
                let (ex, edx, eddx) = (px + k0 * innov, pdx + k1 * innov, pddx + k2 * innov);
                *s = RateState { x: ex, dx: edx, ddx: eddx, primed: 2 };
                (edx, eddx)
            }
        }
    }

    /// Group delay of the first-derivative estimate at low frequency, in seconds
    /// (half a sample for the backward difference, plus the low-pass's for `Filtered`).
    pub fn delay_s(&self) -> f32 {
        match *self {
            Self::Backward { inv_dt } => 0.5 / inv_dt,
            Self::Filtered { inv_dt, a, g } => 0.5 / inv_dt + a / (g * inv_dt),
            // Steady-state CA Kalman filter is unbiased for polynomial inputs up to degree 2.
            Self::Kalman { .. } => 0.0,
        }
    }
}

type M3 = [[f64; 3]; 3];

fn transpose(m: &M3) -> M3 {
    [[m[0][0], m[1][0], m[2][0]], [m[0][1], m[1][1], m[2][1]], [m[0][2], m[1][2], m[2][2]]]
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// `a · b`
fn mul(a: &M3, b: &M3) -> M3 {
    let bt = transpose(b);
    a.map(|row| bt.map(|col| dot(&row, &col)))
}

/// Iterate the Riccati recursion (seed 002 eq. 24, 25, 27) in f64 to its fixed point and
/// return the steady-state gain. `None` when it does not converge or is not finite.
fn steady_state_gain(t: f64, q: f64, r: f64) -> Option<[f32; 3]> {
    let a: M3 = [[1.0, t, t * t / 2.0], [0.0, 1.0, t], [0.0, 0.0, 1.0]];
    let at = transpose(&a);
    let (t2, t3, t4, t5) = (t * t, t * t * t, t * t * t * t, t * t * t * t * t);
    let qm: M3 = [
        [q * t5 / 20.0, q * t4 / 8.0, q * t3 / 6.0],
        [q * t4 / 8.0, q * t3 / 6.0, q * t2 / 2.0],
        [q * t3 / 6.0, q * t2 / 2.0, q * t],
    ];
    let mut p: M3 = [[r, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]];
    let mut k = [0.0f64; 3];
    for _ in 0..200_000 {
        // P⁻ = A P Aᵀ + Q  (eq. 24)
        let apa = mul(&mul(&a, &p), &at);
        let mut pm = apa;
        for (row, qrow) in pm.iter_mut().zip(qm.iter()) {
            for (v, qv) in row.iter_mut().zip(qrow.iter()) {
                *v += qv;
            }
        }
        // K = P⁻Hᵀ (H P⁻ Hᵀ + R)⁻¹ with H = [1 0 0]  (eq. 25)
        let s = pm[0][0] + r;
        if !(s.is_finite() && s > 0.0) {
            return None;
        }
        let k_new = [pm[0][0] / s, pm[1][0] / s, pm[2][0] / s];
        // P = (I − K H) P⁻  (eq. 27)
        let first = pm[0];
        for (row, ki) in pm.iter_mut().zip(k_new.iter()) {
            for (v, f) in row.iter_mut().zip(first.iter()) {
                *v -= ki * f;
            }
        }
        p = pm;
        let change: f64 = k_new.iter().zip(k.iter()).map(|(n, o)| (n - o).abs() / (n.abs() + 1e-300)).sum();
        k = k_new;
        if change < 1e-12 {
            let g = [k[0] as f32, k[1] as f32, k[2] as f32];
            return if g.iter().all(|v| v.is_finite()) { Some(g) } else { None };
        }
    }
    None
}

#[cfg(test)]
mod tests;
