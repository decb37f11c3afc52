//! The exponentially fitted θ-method for the `z`–`w` feedback loop: stages, the split at a
//! reversal of the stroke and the bracketed Newton solve for `Δw` (module docs of
//! [`spencer`](super), item 2).

use super::{Spencer, MAX_STAGES, NEWTON_ITERS, STAGE_LAMBDA_T};
use crate::math::{abs, expm1};

/// `clamp(⌈λT / STAGE_LAMBDA_T⌉, 1, MAX_STAGES)` (NaN → 1).
#[inline]
pub(super) fn stage_count(lam_t: f32) -> usize {
    let mut m = 1;
    while m < MAX_STAGES && m as f32 * STAGE_LAMBDA_T < lam_t {
        m += 1;
    }
    m
}

/// θ of the exponentially fitted θ-method: `1/(1 − e^{−x}) − 1/x` (→ ½ as x → 0).
///
/// Below 1 (every stage of the published set and of the fits on the Dyke files) its
/// Bernoulli series to x⁹, `½ + x/12 − x³/720 + x⁵/30240 − x⁷/1209600 + x⁹/47900160`
/// (truncation < 6e-10), which needs neither `expm1` nor a division.
#[inline]
fn fitted_theta(x: f32) -> f32 {
    if x < 1.0 {
        let x2 = x * x;
        0.5 + x
            * (1.0 / 12.0 + x2 * (-1.0 / 720.0 + x2 * (1.0 / 30_240.0 + x2 * (-1.0 / 1_209_600.0 + x2 / 47_900_160.0))))
    } else if x > 30.0 {
        1.0 - 1.0 / x
    } else {
        -1.0 / expm1(-x) - 1.0 / x
    }
}

impl Spencer {
    /// One stage of length `h`: the drive `c1·ẋ` is linear over the stage (`h·ẋ` at its ends
    /// `hx0`, `hx1`) and the filtered command goes from `u0` to `u1`. When the frozen-state
    /// prediction of `ẇ` changes sign inside the stage (a reversal of the Bouc–Wen stroke),
    /// the stage is split there so that each part moves `w` one way. Returns `(w₁, z₁)`.
    #[inline]
    pub(super) fn stage(&self, w0: f32, z0: f32, (hx0, hx1): (f32, f32), (u0, u1): (f32, f32), h: f32) -> (f32, f32) {
        let f = self.drive(w0, z0, (hx0, hx1), (u0, u1), h);
        let (f0, f1) = f;
        if (f0 > 0.0 && f1 < 0.0) || (f0 < 0.0 && f1 > 0.0) {
            let tau = f0 / (f0 - f1);
            if tau > 0.05 && tau < 0.95 {
                let hx_mid = hx0 + (hx1 - hx0) * tau;
                let u_mid = u0 + (u1 - u0) * tau;
                let hx = (tau * hx0, tau * hx_mid);
                let f = self.drive(w0, z0, hx, (u0, u_mid), tau * h);
                let (wm, zm) = self.stage_mono(w0, z0, f, u_mid, tau * h);
                let rest = 1.0 - tau;
                let (hx, u) = ((rest * hx_mid, rest * hx1), (u_mid, u1));
                let f = self.drive(wm, zm, hx, u, rest * h);
                return self.stage_mono(wm, zm, f, u1, rest * h);
            }
        }
        self.stage_mono(w0, z0, f, u1, h)
    }

    /// `h·ẇ` at both ends of a stage with `z`, `w` frozen at the start (eq. 5).
    #[inline]
    fn drive(&self, w0: f32, z0: f32, (hx0, hx1): (f32, f32), (u0, u1): (f32, f32), h: f32) -> (f32, f32) {
        let k0 = self.p.k0;
        let (al0, c00, c10) = self.coefficients(u0);
        let (al1, c01, c11) = self.coefficients(u1);
        let f0 = (c10 * hx0 - h * (al0 * z0 + k0 * w0)) / (c00 + c10);
        let f1 = (c11 * hx1 - h * (al1 * z0 + k0 * w0)) / (c01 + c11);
        (f0, f1)
    }

    /// The exponentially fitted θ-step over one stage (module docs, item 2), from the stage's
    /// [`drive`](Self::drive) `(f0, f1)` and the filtered command `u1` at its end.
    #[inline]
    fn stage_mono(&self, w0: f32, z0: f32, (f0, f1): (f32, f32), u1: f32, h: f32) -> (f32, f32) {
        let k0 = self.p.k0;
        let (al1, c01, c11) = self.coefficients(u1);
        let s1 = c01 + c11;
        // Branch from the trapezoidal prediction, then θ fitted to λ on that branch.
        let dir = if f0 + f1 < 0.0 { -1.0 } else { 1.0 };
        let h_s1 = h / s1;
        let lam_h = h_s1 * (k0 + al1 * self.slope(dir * z0));
        let theta = fitted_theta(lam_h);
        let r = (1.0 - theta) * f0 + theta * f1;
        let a = 1.0 + theta * h_s1 * k0;
        let b = theta * h_s1 * al1;
        let sgn = if r < 0.0 { -1.0 } else { 1.0 };
        let (d, zeta1) = self.solve(sgn * z0, a, b, sgn * r);
        (w0 + sgn * d, sgn * zeta1)
    }

    /// Solve `a·D + b·(ζ(D) − ζ₀) = r` for `D ∈ [0, r/a]` (r ≥ 0); returns `(D, ζ(D))`.
    pub(super) fn solve(&self, zeta0: f32, a: f32, b: f32, r: f32) -> (f32, f32) {
        if r.is_nan() || r <= 0.0 {
            return (0.0, zeta0);
        }
        let mut lo = 0.0f32;
        let mut hi = r / a;
        // Linearised start (the linearly implicit step).
        let mut d = r / (a + b * self.slope(zeta0));
        for _ in 0..NEWTON_ITERS {
            let zeta = self.flow(zeta0, d);
            let h = a * d + b * (zeta - zeta0) - r;
            if h > 0.0 {
                hi = d;
            } else if h < 0.0 {
                lo = d;
            } else {
                return (d, zeta);
            }
            let g = self.slope(zeta);
            let mut next = d - h / (a + b * g);
            if !(next >= lo && next <= hi) {
                next = 0.5 * (lo + hi);
            } else if abs(next - d) <= 2e-6 * d {
                // Converged by a Newton step: ζ moves with D at slope g over a step this
                // small (the second-order term is ~1e-12 of ζ), so no further flow is needed.
                return (next, crate::math::clamp(zeta + g * (next - d), -self.zmax, self.zmax));
            }
            d = next;
        }
        // ζ consistent with the returned D.
        (d, self.flow(zeta0, d))
    }
}
