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
    pub k: f32,
    /// Damping c, N·m·s per unit B.
    pub c: f32,
    /// Power-law coefficient α, N·m per unit B⁴.
    pub alpha: f32,
    /// Initial torque T₀, N·m.
    pub t0: f32,
    dt: f32,
}

/// The algebraic model has no state.
pub type State = ();
pub type Registered = Algebraic;

impl Algebraic {
    /// Any finite k, c, α, T₀ (seed 000 Table 6 fits negative c and α).
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
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use super::*;

    #[test]
    fn matches_eq14() {
        let m = Algebraic::new(4.606, -0.076, 0.033, 0.797, 1e-3).unwrap();
        let y = m.step(&mut (), &Kin::new(1.5, 2.0, 0.0, 0.0));
        let want = 4.606 * 1.5 - 0.076 * 2.0 + 0.033 * 1.5 * 1.5f32.powi(3) + 0.797;
        assert!((y - want).abs() < 1e-5, "{y} vs {want}");
    }

    #[test]
    fn rejects_non_finite() {
        assert!(Algebraic::new(f32::NAN, 0.0, 0.0, 0.0, 1e-3).is_err());
        assert!(Algebraic::new(1.0, 0.0, 0.0, 0.0, 0.0).is_err());
        assert!(Algebraic::from_params(&[1.0, 2.0], 1e-3).is_err());
    }
}
