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
//! their command dependence are those of [`Arctan`]. Any finite `m` is accepted (the paper
//! fits it freely). `ẍ` is [`Kin::ddx`]: with backward differences it is noisy, and `m·ẍ`
//! passes that noise straight to the output (on top of the `sgn(ẍ)` chattering described
//! in [`arctan`](super::arctan)), so pair the model with a smoothing rate estimator.
//! With `m = 0` the model is exactly eq. 16.

use crate::error::{count, finite};
use crate::model::write_flat;
use crate::models::arctan::{Arctan, Params};
use crate::{Kin, Model, ParamError};

/// Validated coefficients of eq. 17.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArctanInertia {
    /// The eq. 16 part.
    pub base: Arctan,
    /// m: virtual mass, N·s² per unit x.
    pub m: f32,
}

/// No state.
pub type State = ();
pub type Registered = ArctanInertia;

impl ArctanInertia {
    /// The bounds of [`Arctan::new`], and a finite `m`.
    pub fn new(p: Params, m: f32, dt: f32) -> Result<Self, ParamError> {
        Ok(Self { base: Arctan::new(p, dt)?, m: finite("m", m)? })
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
        let [a0, a1, b0, b1, c0, c1, d0, d1, e0, e1] = self.base.p.flat();
        write_flat(&[a0, a1, b0, b1, c0, c1, d0, d1, e0, e1, self.m], out)
    }

    fn dt(&self) -> f32 {
        self.base.dt()
    }

    #[inline]
    fn step(&self, _state: &mut (), k: &Kin) -> f32 {
        self.base.force(k) + self.m * k.ddx
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn example() -> Params {
        Params { f0: [20.0, 5.0], cb: [900.0, 400.0], fy: [150.0, 700.0], k: [60.0, 10.0], xd0: [0.01, 0.005] }
    }

    /// m = 0 is eq. 16 exactly; otherwise the difference is m·ẍ.
    #[test]
    fn reduces_to_arctan_and_adds_inertia() {
        let base = Arctan::new(example(), 1e-3).unwrap();
        let zero = ArctanInertia::new(example(), 0.0, 1e-3).unwrap();
        let heavy = ArctanInertia::new(example(), 2.5, 1e-3).unwrap();
        for (v, a, u) in [(0.05f32, 3.0f32, 0.0f32), (-0.1, -40.0, 1.0), (0.0, 7.0, 2.0), (0.02, 0.0, 0.5)] {
            let k = Kin::new(0.01, v, a, u);
            let b = base.step(&mut (), &k);
            assert_eq!(zero.step(&mut (), &k), b);
            assert!((heavy.step(&mut (), &k) - (b + 2.5 * a)).abs() < 1e-3);
        }
        let mut p = [0.0; 11];
        assert_eq!(heavy.write_params(&mut p), 11);
        assert_eq!(p[10], 2.5);
        assert_eq!(ArctanInertia::from_params(&p, 1e-3).unwrap(), heavy);
        assert!(ArctanInertia::from_params(&p[..10], 1e-3).is_err());
        assert!(ArctanInertia::new(example(), f32::INFINITY, 1e-3).is_err());
    }
}
