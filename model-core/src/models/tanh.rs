//! Hyperbolic tangent model (Kwok et al. 2006) adapted to the MR clutch, seed 000 eq. 11–12:
//!
//! `T = c·Ḃ + k·B + α·z + T₀`,  `z = tanh(β·Ḃ + γ·sign(B))`.
//!
//! Stateless: the loop comes from the rate term inside the tanh. `sign(0) = 0`. The tanh
//! is [`tanh_fast`] (no libm call in the hot path; within 5e-7 of
//! the exact tanh).
//! Parameters (flat order, seed 000 Table 2/5): `alpha, beta, gamma, c, k, t0`, any finite
//! values (Table 5 fits negative c).

use crate::error::{count, finite, time_step};
use crate::math::{sign, tanh_fast};
use crate::model::write_flat;
use crate::{Kin, Model, ParamError};

/// Coefficients of eq. 11–12.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tanh {
    /// Height α of the hysteretic part, N·m.
    alpha: f32,
    /// Rate gain β, s per unit B.
    beta: f32,
    /// Width γ of the loop (offset inside the tanh).
    gamma: f32,
    /// Viscous coefficient c, N·m·s per unit B.
    c: f32,
    /// Stiffness k, N·m per unit B.
    k: f32,
    /// Initial torque T₀, N·m.
    t0: f32,
    dt: f32,
}

/// Read access to the validated parameters (set only by `new`/`from_params`).
impl Tanh {
    /// Height α of the hysteretic part, N·m.
    #[inline]
    pub fn alpha(&self) -> f32 {
        self.alpha
    }

    /// Rate gain β, s per unit B.
    #[inline]
    pub fn beta(&self) -> f32 {
        self.beta
    }

    /// Width γ of the loop (offset inside the tanh).
    #[inline]
    pub fn gamma(&self) -> f32 {
        self.gamma
    }

    /// Viscous coefficient c, N·m·s per unit B.
    #[inline]
    pub fn c(&self) -> f32 {
        self.c
    }

    /// Stiffness k, N·m per unit B.
    #[inline]
    pub fn k(&self) -> f32 {
        self.k
    }

    /// Initial torque T₀, N·m.
    #[inline]
    pub fn t0(&self) -> f32 {
        self.t0
    }
}

/// No state.
pub type State = ();
pub type Registered = Tanh;

impl Tanh {
    /// Any finite values (seed 000 Table 5 fits negative c).
    ///
    /// # Examples
    ///
    /// ```
    /// use model_core::models::tanh::{Tanh, SEED000_AVERAGE};
    /// use model_core::rate::RateParams;
    /// use model_core::{Estimator, Sample};
    ///
    /// let dt = 1e-4;
    /// let [alpha, beta, gamma, c, k, t0] = SEED000_AVERAGE;
    /// let model = Tanh::new(alpha, beta, gamma, c, k, t0, dt)?;
    /// let est = Estimator::new(model, RateParams::backward(dt)?)?;
    /// let mut state = est.state();
    /// for i in 0..100 {
    ///     let out = est.step(&mut state, Sample::new(0.01 * i as f32));
    ///     assert!(out.flags.ok() && out.y.is_finite());
    /// }
    /// // A non-finite sample is ignored and the last output held.
    /// let held = est.step(&mut state, Sample::new(f32::NAN));
    /// assert!(!held.flags.ok() && held.y.is_finite());
    /// # Ok::<(), model_core::ParamError>(())
    /// ```
    pub fn new(alpha: f32, beta: f32, gamma: f32, c: f32, k: f32, t0: f32, dt: f32) -> Result<Self, ParamError> {
        Ok(Self {
            alpha: finite("alpha", alpha)?,
            beta: finite("beta", beta)?,
            gamma: finite("gamma", gamma)?,
            c: finite("c", c)?,
            k: finite("k", k)?,
            t0: finite("t0", t0)?,
            dt: time_step(dt)?,
        })
    }
}

/// Seed 000 (Yang & Kermani 2023) Table 5, the average of the five per-frequency fits
/// (clutch input B, T in N·m), in [`Model::from_params`] order `alpha, beta, gamma, c, k, t0`.
pub const SEED000_AVERAGE: [f32; 6] = [0.495, 1.969, 1.603, -0.120, 4.790, 0.587];

impl Model for Tanh {
    type State = State;
    const ID: &'static str = "tanh";
    const PARAM_NAMES: &'static [&'static str] = &["alpha", "beta", "gamma", "c", "k", "t0"];
    const N_PARAMS: usize = 6;

    fn from_params(v: &[f32], dt: f32) -> Result<Self, ParamError> {
        count(v, Self::N_PARAMS)?;
        match *v {
            [alpha, beta, gamma, c, k, t0] => Self::new(alpha, beta, gamma, c, k, t0, dt),
            _ => Err(ParamError::WrongCount { expected: Self::N_PARAMS, got: v.len() }),
        }
    }

    fn write_params(&self, out: &mut [f32]) -> usize {
        write_flat(&[self.alpha, self.beta, self.gamma, self.c, self.k, self.t0], out)
    }

    fn dt(&self) -> f32 {
        self.dt
    }

    #[inline]
    fn step(&self, _s: &mut (), k: &Kin) -> f32 {
        let z = tanh_fast(self.beta * k.dx + self.gamma * sign(k.x));
        self.c * k.dx + self.k * k.x + self.alpha * z + self.t0
    }
}

#[cfg(test)]
mod tests;
