//! Bingham visco-plastic model of an MR damper (Stanway et al.; seed 003 §4.1, eq. 12–14;
//! seed 001 §1):
//!
//! ```text
//! F = f_c(u)·sgn(ẋ) + c0(u)·ẋ + f0
//! f_c(u) = fc0 + fc1·u + fc2·u² + fc3·u³          (seed 003 eq. 13, cubic in current)
//! c0(u)  = c0_0 + c0_1·u + c0_2·u² + c0_3·u³ + c0_4·u⁴   (seed 003 eq. 14, quartic)
//! ```
//!
//! A Coulomb friction element `f_c` in parallel with a dashpot `c0`, plus the accumulator
//! force `f0`. `u` is the command ([`Kin::u`], coil current in A in seed 003, or a voltage —
//! whatever the coefficients were fitted in), used as is (no filter); `sgn(0) = 0`.
//!
//! **Design choice.** Seed 003 fits `f_c` and `c0` as a cubic and a quartic polynomial of the
//! current (eq. 13–14: `f_c = −910.09I³ + 986.49I² + 663.56I + 52.19` N and
//! `c0 = 48.74I⁴ − 106.39I³ + 66.00I² + 1.43I + 0.53` N·s/mm, `f0 = 40` N), so the flat
//! vector carries those polynomial coefficients; the linear form `f_c = f_ca + f_cb·u` is
//! `fc2 = fc3 = 0`, `c0_2 = c0_3 = c0_4 = 0`, and the constant (single-current) form sets all
//! higher coefficients to zero. The polynomials are fits over the tested range
//! (0–1 A in seed 003) and are not checked outside it; the constructor only requires the
//! zero-command values to be physical (`fc0 ≥ 0`, `c0_0 ≥ 0`).
//!
//! No state: the model is memoryless (no hysteresis loop in force–displacement beyond the
//! jump of `sgn(ẋ)` at reversal).

use crate::error::{check, count, finite, time_step};
use crate::model::write_flat;
use crate::models::kernels::poly::poly;
use crate::{Kin, Model, ParamError};

/// Coefficients of seed 003 eq. 12–14.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bingham {
    /// `[fc0, fc1, fc2, fc3]`: friction force polynomial in u, N per uᵏ (eq. 13).
    fc: [f32; 4],
    /// `[c0_0, …, c0_4]`: damping polynomial in u, N·s per unit x per uᵏ (eq. 14).
    c0: [f32; 5],
    /// f0: accumulator force offset, N.
    f0: f32,
    dt: f32,
}

/// Read access to the validated parameters (set only by `new`/`from_params`).
impl Bingham {
    /// `[fc0, fc1, fc2, fc3]`: friction force polynomial in u, N per uᵏ (eq. 13).
    #[inline]
    pub fn fc(&self) -> &[f32; 4] {
        &self.fc
    }

    /// `[c0_0, …, c0_4]`: damping polynomial in u, N·s per unit x per uᵏ (eq. 14).
    #[inline]
    pub fn c0(&self) -> &[f32; 5] {
        &self.c0
    }

    /// f0: accumulator force offset, N.
    #[inline]
    pub fn f0(&self) -> f32 {
        self.f0
    }
}

/// The Bingham model has no state.
pub type State = ();
pub type Registered = Bingham;

/// Seed 003 eq. 13–14 with f0 = 40 N (RD-1005-3, x in mm, F in N, current in A).
pub const SEED003: ([f32; 4], [f32; 5], f32) =
    ([52.19, 663.56, 986.49, -910.09], [0.53, 1.43, 66.00, -106.39, 48.74], 40.0);

impl Bingham {
    /// Every coefficient finite; `fc0 ≥ 0` and `c0_0 ≥ 0` (a passive damper at zero command).
    ///
    /// # Examples
    ///
    /// ```
    /// use model_core::models::bingham::{Bingham, SEED003};
    /// use model_core::{Kin, Model};
    ///
    /// let (fc, c0, f0) = SEED003;
    /// let model = Bingham::new(fc, c0, f0, 1e-3)?;
    /// // 10 mm/s at 0.5 A.
    /// let force = model.step(&mut (), &Kin::new(0.0, 10.0, 0.0, 0.5));
    /// assert!(force.is_finite());
    /// # Ok::<(), model_core::ParamError>(())
    /// ```
    pub fn new(fc: [f32; 4], c0: [f32; 5], f0: f32, dt: f32) -> Result<Self, ParamError> {
        let dt = time_step(dt)?;
        for (name, v) in FC_NAMES.iter().zip(fc.iter()) {
            finite(name, *v)?;
        }
        for (name, v) in C0_NAMES.iter().zip(c0.iter()) {
            finite(name, *v)?;
        }
        let ([fc0, ..], [c00, ..]) = (fc, c0);
        check("fc0", fc0, 0.0, f32::INFINITY)?;
        check("c0_0", c00, 0.0, f32::INFINITY)?;
        Ok(Self { fc, c0, f0: finite("f0", f0)?, dt })
    }

    /// Friction force f_c(u) and damping c0(u).
    #[inline]
    pub fn coefficients(&self, u: f32) -> (f32, f32) {
        (poly(&self.fc, u), poly(&self.c0, u))
    }
}

const FC_NAMES: [&str; 4] = ["fc0", "fc1", "fc2", "fc3"];
const C0_NAMES: [&str; 5] = ["c0_0", "c0_1", "c0_2", "c0_3", "c0_4"];

impl Model for Bingham {
    type State = State;
    const ID: &'static str = "bingham";
    const PARAM_NAMES: &'static [&'static str] =
        &["fc0", "fc1", "fc2", "fc3", "c0_0", "c0_1", "c0_2", "c0_3", "c0_4", "f0"];
    const N_PARAMS: usize = 10;

    fn from_params(v: &[f32], dt: f32) -> Result<Self, ParamError> {
        count(v, Self::N_PARAMS)?;
        match *v {
            [a0, a1, a2, a3, b0, b1, b2, b3, b4, f0] => Self::new([a0, a1, a2, a3], [b0, b1, b2, b3, b4], f0, dt),
            _ => Err(ParamError::WrongCount { expected: Self::N_PARAMS, got: v.len() }),
        }
    }

    fn write_params(&self, out: &mut [f32]) -> usize {
        let [a0, a1, a2, a3] = self.fc;
        let [b0, b1, b2, b3, b4] = self.c0;
        write_flat(&[a0, a1, a2, a3, b0, b1, b2, b3, b4, self.f0], out)
    }

    fn dt(&self) -> f32 {
        self.dt
    }

    #[inline]
    fn step(&self, _state: &mut (), k: &Kin) -> f32 {
        let (fc, c0) = self.coefficients(k.u);
        fc * crate::math::sign(k.dx) + c0 * k.dx + self.f0
    }
}

#[cfg(test)]
mod tests;
