//! Guo & Hu's arctan force law with command-linear coefficients (seed 001 eq. 16), shared by
//! [`arctan`](super::super::arctan) and [`arctan_inertia`](super::super::arctan_inertia)
//! (eq. 17 adds `m·ẍ`).

use crate::error::{check, finite};
use crate::math::{atan, sign};
use crate::{Kin, ParamError};

/// Flat parameter names of eq. 16 (each `_a` at zero command, `_b` its slope per unit u).
pub(crate) const NAMES: [&str; 10] = ["f0_a", "f0_b", "cb_a", "cb_b", "fy_a", "fy_b", "k_a", "k_b", "xd0_a", "xd0_b"];

/// Parameters of eq. 16, each `[value at u = 0, slope per unit u]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Params {
    /// f0: pre-load, N.
    pub f0: [f32; 2],
    /// cb: viscous damping, N·s per unit x (zero-command value ≥ 0).
    pub cb: [f32; 2],
    /// fy: yield force, N (zero-command value ≥ 0).
    pub fy: [f32; 2],
    /// k: shape coefficient, s per unit x (zero-command value ≥ 0).
    pub k: [f32; 2],
    /// ẋ0: hysteretic velocity, unit x per s (zero-command value ≥ 0).
    pub xd0: [f32; 2],
}

impl Params {
    /// The flat order of [`Arctan::PARAM_NAMES`](crate::models::arctan::Arctan).
    pub fn flat(&self) -> [f32; 10] {
        let [a, b, c, d, e] = [self.f0, self.cb, self.fy, self.k, self.xd0];
        [a[0], a[1], b[0], b[1], c[0], c[1], d[0], d[1], e[0], e[1]]
    }

    /// From the flat order of [`Arctan::PARAM_NAMES`](crate::models::arctan::Arctan).
    pub fn from_flat(v: [f32; 10]) -> Self {
        let [a0, a1, b0, b1, c0, c1, d0, d1, e0, e1] = v;
        Self { f0: [a0, a1], cb: [b0, b1], fy: [c0, c1], k: [d0, d1], xd0: [e0, e1] }
    }

    /// Finite values; `cb_a, fy_a, k_a, xd0_a ≥ 0`.
    pub(crate) fn validate(&self) -> Result<(), ParamError> {
        for (name, v) in NAMES.iter().zip(self.flat().iter()) {
            finite(name, *v)?;
        }
        check("cb_a", self.cb[0], 0.0, f32::INFINITY)?;
        check("fy_a", self.fy[0], 0.0, f32::INFINITY)?;
        check("k_a", self.k[0], 0.0, f32::INFINITY)?;
        check("xd0_a", self.xd0[0], 0.0, f32::INFINITY)?;
        Ok(())
    }

    /// `(f0, cb, fy, k, ẋ0)` at command `u`.
    #[inline]
    pub fn coefficients(&self, u: f32) -> (f32, f32, f32, f32, f32) {
        let lin = |c: [f32; 2]| c[0] + c[1] * u;
        (lin(self.f0), lin(self.cb), lin(self.fy), lin(self.k), lin(self.xd0))
    }

    /// Eq. 16: `f0 + cb·ẋ + (2/π)·fy·atan(k·(ẋ − ẋ0·sgn(ẍ)))` at the command `k.u`.
    #[inline]
    pub fn force(&self, k: &Kin) -> f32 {
        let (f0, cb, fy, kk, xd0) = self.coefficients(k.u);
        f0 + cb * k.dx + core::f32::consts::FRAC_2_PI * fy * atan(kk * (k.dx - xd0 * sign(k.ddx)))
    }
}
