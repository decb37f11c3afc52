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
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use super::*;
    use std::vec::Vec;

    #[test]
    fn matches_eq11_12() {
        // Seed 000 Table 5 average.
        let m = Tanh::new(0.495, 1.969, 1.603, -0.120, 4.790, 0.587, 2e-3).unwrap();
        for (b, bd) in [(1.5f64, 2.0f64), (-0.7, -3.0), (0.0, 1.0), (2.9, -0.2)] {
            let y = m.step(&mut (), &Kin::new(b as f32, bd as f32, 0.0, 0.0));
            let z = (1.969 * bd + 1.603 * b.signum() * if b == 0.0 { 0.0 } else { 1.0 }).tanh();
            let want = -0.120 * bd + 4.790 * b + 0.495 * z + 0.587;
            assert!((f64::from(y) - want).abs() < 1e-5, "{y} vs {want}");
        }
    }

    /// Seed 000 Fig. 4: γ sets the width of the loop and α its height. The sign(B) term
    /// separates the branches in the torque–rate plane (Kwok's force–velocity loop), whose
    /// area is `α·∫[tanh(βu + γ) − tanh(βu − γ)]du`, increasing in γ and α.
    #[test]
    fn loop_width_and_height() {
        let area_height = |alpha: f32, gamma: f32| {
            let m = Tanh::new(alpha, 1.0, gamma, 0.0, 0.0, 0.0, 1e-3).unwrap();
            let n = 1000;
            let w = 2.0 * core::f32::consts::PI;
            let pts: Vec<(f64, f64)> = (0..n)
                .map(|i| {
                    let t = (i as f32 + 0.5) / n as f32;
                    let (b, bd) = ((w * t).sin(), (w * t).cos());
                    (f64::from(bd), f64::from(m.step(&mut (), &Kin::new(b, bd, 0.0, 0.0))))
                })
                .collect();
            let mut a = 0.0;
            for i in 0..n {
                let (p, q) = (pts[i], pts[(i + 1) % n]);
                a += p.0 * q.1 - q.0 * p.1;
            }
            let hi = pts.iter().map(|p| p.1).fold(f64::MIN, f64::max);
            (0.5 * a.abs(), hi)
        };
        let mut prev = 0.0;
        for g in [0.1f32, 0.3, 0.6, 1.0, 2.0] {
            let (a, _) = area_height(1.0, g);
            assert!(a > prev, "γ widens: {a} after {prev}");
            // closed form α∫_{-1}^{1}[tanh(u+γ) − tanh(u−γ)]du = α[ln cosh(u+γ) − ln cosh(u−γ)]
            let gg = f64::from(g);
            let want = 2.0 * ((1.0 + gg).cosh().ln() - (1.0 - gg).cosh().ln());
            assert!((a - want).abs() < 1e-2 * want, "{a} vs {want}");
            prev = a;
        }
        let (a2, h2) = area_height(1.0, 1.0);
        let (a3, h3) = area_height(2.0, 1.0);
        assert!(a3 > a2 && h3 > h2, "α scales the height: {a2} {a3} {h2} {h3}");
    }

    #[test]
    fn rejects_non_finite() {
        assert!(Tanh::new(f32::NAN, 0.0, 0.0, 0.0, 0.0, 0.0, 1e-3).is_err());
        assert!(Tanh::from_params(&[0.0; 5], 1e-3).is_err());
        let p = [0.495, 1.969, 1.603, -0.120, 4.790, 0.587];
        let mut out = [0.0; 6];
        Tanh::from_params(&p, 1e-3).unwrap().write_params(&mut out);
        assert_eq!(out, p);
    }
}
