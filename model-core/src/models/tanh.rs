//! Hyperbolic tangent model (Kwok et al. 2006) adapted to the MR clutch, seed 000 eq. 11–12:
//!
//! `T = c·Ḃ + k·B + α·z + T₀`,  `z = tanh(β·Ḃ + γ·sign(B))`.
//!
//! Stateless: the loop comes from the rate term inside the tanh. `sign(0) = 0`. The tanh
//! is [`tanh_fast`](crate::math::tanh_fast) (no libm call in the hot path; within 5e-7 of
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
    pub alpha: f32,
    /// Rate gain β, s per unit B.
    pub beta: f32,
    /// Width γ of the loop (offset inside the tanh).
    pub gamma: f32,
    /// Viscous coefficient c, N·m·s per unit B.
    pub c: f32,
    /// Stiffness k, N·m per unit B.
    pub k: f32,
    /// Initial torque T₀, N·m.
    pub t0: f32,
    dt: f32,
}

/// No state.
pub type State = ();
pub type Registered = Tanh;

impl Tanh {
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
