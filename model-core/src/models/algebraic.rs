//! Algebraic hysteresis model, seed 000 eq. 14 (Yang & Kermani 2023):
//!
//! `T = k·B + c·Ḃ + α·|B|·B³ + T₀`
//!
//! B in the unit the parameters were fitted in (the paper uses mT), Ḃ in that unit per
//! second, T in N·m. No internal state: the loop comes from the rate term `c·Ḃ` and
//! its width grows with `c` and `α` (seed 000 Fig. 5).

use crate::error::{count, finite, time_step};
use crate::model::write_flat;
use crate::{Kin, Model, ParamError};

/// Coefficients of eq. 14.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Algebraic {
    /// Stiffness k, N·m per unit B.
    k: f32,
    /// Damping c, N·m·s per unit B.
    c: f32,
    /// Power-law coefficient α, N·m per unit B⁴.
    alpha: f32,
    /// Initial torque T₀, N·m.
    t0: f32,
    dt: f32,
}

/// Read access to the validated parameters (set only by `new`/`from_params`).
impl Algebraic {
    /// Stiffness k, N·m per unit B.
    #[inline]
    pub fn k(&self) -> f32 {
        self.k
    }

    /// Damping c, N·m·s per unit B.
    #[inline]
    pub fn c(&self) -> f32 {
        self.c
    }

    /// Power-law coefficient α, N·m per unit B⁴.
    #[inline]
    pub fn alpha(&self) -> f32 {
        self.alpha
    }

    /// Initial torque T₀, N·m.
    #[inline]
    pub fn t0(&self) -> f32 {
        self.t0
    }
}

/// The algebraic model has no state.
pub type State = ();
pub type Registered = Algebraic;

impl Algebraic {
    /// Any finite k, c, α, T₀ (seed 000 Table 6 fits negative c and α).
    ///
    /// # Examples
    ///
    /// ```
    /// use model_core::models::algebraic::{Algebraic, SEED000_AVERAGE};
    /// use model_core::{Kin, Model};
    ///
    /// let [k, c, alpha, t0] = SEED000_AVERAGE;
    /// let model = Algebraic::new(k, c, alpha, t0, 1e-4)?;
    /// let mut state = model.initial_state(&Kin::new(1.5, 0.0, 0.0, 0.0));
    /// // B = 1.5 mT rising at 2 mT/s.
    /// let torque = model.step(&mut state, &Kin::new(1.5, 2.0, 0.0, 0.0));
    /// assert!((torque - (k * 1.5 + c * 2.0 + alpha * 1.5f32.powi(4) + t0)).abs() < 1e-4);
    /// # Ok::<(), model_core::ParamError>(())
    /// ```
    pub fn new(k: f32, c: f32, alpha: f32, t0: f32, dt: f32) -> Result<Self, ParamError> {
        Ok(Self {
            k: finite("k", k)?,
            c: finite("c", c)?,
            alpha: finite("alpha", alpha)?,
            t0: finite("t0", t0)?,
            dt: time_step(dt)?,
        })
    }
}

/// Seed 000 (Yang & Kermani 2023) Table 6, the average of the five per-frequency fits
/// (B in mT, T in N·m), in [`Model::from_params`] order `k, c, alpha, t0`.
pub const SEED000_AVERAGE: [f32; 4] = [4.606, -0.076, 0.033, 0.797];

impl Model for Algebraic {
    type State = State;
    const ID: &'static str = "algebraic";
    const PARAM_NAMES: &'static [&'static str] = &["k", "c", "alpha", "t0"];
    const N_PARAMS: usize = 4;

    fn from_params(v: &[f32], dt: f32) -> Result<Self, ParamError> {
        count(v, Self::N_PARAMS)?;
        match *v {
            [k, c, alpha, t0] => Self::new(k, c, alpha, t0, dt),
            _ => Err(ParamError::WrongCount { expected: Self::N_PARAMS, got: v.len() }),
        }
    }

    fn write_params(&self, out: &mut [f32]) -> usize {
        write_flat(&[self.k, self.c, self.alpha, self.t0], out)
    }

    fn dt(&self) -> f32 {
        self.dt
    }

    #[inline]
    fn step(&self, _state: &mut (), k: &Kin) -> f32 {
        let b = k.x;
        self.k * b + self.c * k.dx + self.alpha * (b * b) * (b * crate::math::abs(b)) + self.t0
    }
}

#[cfg(test)]
mod tests;

#[cfg(test)]
mod fig5_tests;
