//! Guo & Hu's algebraic model of an MR damper, seed 001 §3.2.2, eq. 16:
//!
//! ```text
//! F = f0 + cb·ẋ + (2/π)·fy·atan(k·(ẋ − ẋ0·sgn(ẍ)))
//! ```
//!
//! `f0` the gas-accumulator pre-load (N), `cb` the viscous damping (N·s per unit x), `fy`
//! the yield force (N), `k` the shape coefficient (s per unit x), `ẋ0` the hysteretic
//! velocity (unit x per s); `ẋ`, `ẍ` the piston velocity and acceleration ([`Kin::dx`],
//! [`Kin::ddx`]). No state: the loop comes from the shift `ẋ0·sgn(ẍ)` of the arctan between
//! the accelerating and decelerating branches.
//!
//! **Command dependence.** Seed 001 Fig. 10 shows the identified parameters varying almost
//! linearly with the coil current (all but the virtual mass of eq. 17), so each parameter
//! here is linear in the command `u` ([`Kin::u`], used as is, no filter):
//! `f0 = f0_a + f0_b·u`, `cb = cb_a + cb_b·u`, `fy = fy_a + fy_b·u`, `k = k_a + k_b·u`,
//! `ẋ0 = xd0_a + xd0_b·u`. The constant form is all `_b = 0`. The paper publishes no numbers
//! (only the plot). The constructor requires finite values and physical zero-command values
//! (`cb_a, fy_a, k_a, xd0_a ≥ 0`); the slopes are not range-checked.
//!
//! **Chattering.** `sgn(ẍ)` switches the branch on the sign of the acceleration estimate.
//! With a noisy displacement (backward differences, seed 002 eq. 14) `ẍ` flips sign from
//! sample to sample near velocity extrema and wherever the motion is slow, so the output
//! jumps by up to `(4/π)·fy·atan(k·ẋ0)` between samples. Use a smoothing rate estimator
//! (`RateParams::filtered` or `kalman`) with this model. `sgn(0) = 0` (the midpoint).

use crate::error::{count, time_step};
use crate::model::write_flat;
pub use crate::models::kernels::arctan_law::Params;
use crate::models::kernels::arctan_law::NAMES;
use crate::{Kin, Model, ParamError};

/// Validated coefficients of eq. 16.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Arctan {
    p: Params,
    dt: f32,
}

/// The arctan model has no state.
pub type State = ();
pub type Registered = Arctan;

impl Arctan {
    /// Finite values; `cb_a, fy_a, k_a, xd0_a ≥ 0`.
    ///
    /// # Examples
    ///
    /// ```
    /// use model_core::models::arctan::{Arctan, Params};
    /// use model_core::{Kin, Model};
    ///
    /// let p = Params { f0: [20.0, 5.0], cb: [900.0, 400.0], fy: [150.0, 700.0], k: [60.0, 10.0], xd0: [0.01, 0.005] };
    /// let model = Arctan::new(p, 1e-3)?;
    /// // 5 cm/s, accelerating, at 1 A.
    /// let force = model.step(&mut (), &Kin::new(0.0, 0.05, 1.0, 1.0));
    /// assert!(force.is_finite());
    /// # Ok::<(), model_core::ParamError>(())
    /// ```
    pub fn new(p: Params, dt: f32) -> Result<Self, ParamError> {
        let dt = time_step(dt)?;
        p.validate()?;
        Ok(Self { p, dt })
    }

    /// The parameters as given.
    pub fn params(&self) -> &Params {
        &self.p
    }

    /// `(f0, cb, fy, k, ẋ0)` at command `u`.
    #[inline]
    pub fn coefficients(&self, u: f32) -> (f32, f32, f32, f32, f32) {
        self.p.coefficients(u)
    }

    /// Eq. 16.
    #[inline]
    pub fn force(&self, k: &Kin) -> f32 {
        self.p.force(k)
    }
}

impl Model for Arctan {
    type State = State;
    const ID: &'static str = "arctan";
    const PARAM_NAMES: &'static [&'static str] = &NAMES;
    const N_PARAMS: usize = 10;

    fn from_params(v: &[f32], dt: f32) -> Result<Self, ParamError> {
        count(v, Self::N_PARAMS)?;
        let flat: [f32; 10] =
            v.try_into().map_err(|_| ParamError::WrongCount { expected: Self::N_PARAMS, got: v.len() })?;
        Self::new(Params::from_flat(flat), dt)
    }

    fn write_params(&self, out: &mut [f32]) -> usize {
        write_flat(&self.p.flat(), out)
    }

    fn dt(&self) -> f32 {
        self.dt
    }

    #[inline]
    fn step(&self, _state: &mut (), k: &Kin) -> f32 {
        self.force(k)
    }
}

#[cfg(test)]
mod tests;
