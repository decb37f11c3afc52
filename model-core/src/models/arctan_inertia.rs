//! Modified algebraic model (mAlg) of an MR damper, seed 001 §3.2.3, eq. 17: Guo's arctan
//! model ([`arctan`](super::arctan), eq. 16) plus the fluid-inertia term `m·ẍ` the authors
//! found missing at low currents:
//!
//! ```text
//! F = f0 + cb·ẋ + (2/π)·fy·atan(k·(ẋ − ẋ0·sgn(ẍ))) + m·ẍ
//! ```
//!
//! `m` is a virtual mass (N·s² per unit x), constant in the command (seed 001 Fig. 10: every
//! parameter but `m` varies almost linearly with the current); the other ten parameters and
//! their command dependence are those of [`Arctan`](super::arctan::Arctan). Any finite `m` is accepted (the paper
//! fits it freely). `ẍ` is [`Kin::ddx`]: with backward differences it is noisy, and `m·ẍ`
//! passes that noise straight to the output (on top of the `sgn(ẍ)` chattering described
//! in [`arctan`](super::arctan)), so pair the model with a smoothing rate estimator.
//! With `m = 0` the model is exactly eq. 16.

use crate::error::{count, finite, time_step};
use crate::model::write_flat;
pub use crate::models::kernels::arctan_law::Params;
use crate::{Kin, Model, ParamError};

/// Validated coefficients of eq. 17.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArctanInertia {
    /// The eq. 16 part.
    p: Params,
    /// m: virtual mass, N·s² per unit x.
    m: f32,
    dt: f32,
}

/// No state.
pub type State = ();
pub type Registered = ArctanInertia;

impl ArctanInertia {
    /// The bounds of [`Arctan::new`](crate::models::arctan::Arctan::new), and a finite `m`.
    ///
    /// # Examples
    ///
    /// ```
    /// use model_core::models::arctan_inertia::{ArctanInertia, Params};
    /// use model_core::{Kin, Model};
    ///
    /// let p = Params { f0: [20.0, 5.0], cb: [900.0, 400.0], fy: [150.0, 700.0], k: [60.0, 10.0], xd0: [0.01, 0.005] };
    /// let model = ArctanInertia::new(p, 0.5, 1e-3)?;
    /// let force = model.step(&mut (), &Kin::new(0.0, 0.05, 1.0, 1.0));
    /// assert!(force.is_finite());
    /// # Ok::<(), model_core::ParamError>(())
    /// ```
    pub fn new(p: Params, m: f32, dt: f32) -> Result<Self, ParamError> {
        let dt = time_step(dt)?;
        p.validate()?;
        Ok(Self { p, m: finite("m", m)?, dt })
    }

    /// The eq. 16 parameters.
    pub fn params(&self) -> &Params {
        &self.p
    }

    /// The virtual mass m, N·s² per unit x.
    pub fn m(&self) -> f32 {
        self.m
    }
}

impl Model for ArctanInertia {
    type State = State;
    const ID: &'static str = "arctan_inertia";
    const PARAM_NAMES: &'static [&'static str] =
        &["f0_a", "f0_b", "cb_a", "cb_b", "fy_a", "fy_b", "k_a", "k_b", "xd0_a", "xd0_b", "m"];
    const N_PARAMS: usize = 11;

    fn from_params(v: &[f32], dt: f32) -> Result<Self, ParamError> {
        count(v, Self::N_PARAMS)?;
        match *v {
            [a0, a1, b0, b1, c0, c1, d0, d1, e0, e1, m] => {
                Self::new(Params::from_flat([a0, a1, b0, b1, c0, c1, d0, d1, e0, e1]), m, dt)
            }
            _ => Err(ParamError::WrongCount { expected: Self::N_PARAMS, got: v.len() }),
        }
    }

    fn write_params(&self, out: &mut [f32]) -> usize {
        let [a0, a1, b0, b1, c0, c1, d0, d1, e0, e1] = self.p.flat();
        write_flat(&[a0, a1, b0, b1, c0, c1, d0, d1, e0, e1, self.m], out)
    }

    fn dt(&self) -> f32 {
        self.dt
    }

    #[inline]
    fn step(&self, _state: &mut (), k: &Kin) -> f32 {
        self.p.force(k) + self.m * k.ddx
    }
}

#[cfg(test)]
mod tests;
