//! The exact (n = 1, 2) or second-order (other n) flow `z₁ = Φ(z₀, Δw)` of `dz/dw = g(z, sgn ẇ)`
//! along an increment of the Bouc–Wen stroke (module docs of [`spencer`](super), item 1).

use super::{Shape, Spencer};
use crate::math::{abs, atan, expm1, expm1_small, ln, powf, sin, tanh_small as tanh};

/// `(eˣ − 1)/x`, total (capped for large x so that it never returns ∞ or NaN).
#[inline]
fn phi1(x: f32) -> f32 {
    if abs(x) < 1e-4 {
        1.0 + 0.5 * x
    } else if x > 60.0 {
        expm1(60.0) / 60.0
    } else {
        expm1(x) / x
    }
}

/// `ln(1 + t)/t` for t > −1 (→ 1 as t → 0).
#[inline]
fn ln1p_over(t: f32) -> f32 {
    if abs(t) < 1e-3 {
        1.0 - 0.5 * t + t * t / 3.0
    } else {
        ln(1.0 + t) / t
    }
}

/// `atanh(x)` for 0 ≤ x < 1.
#[inline]
fn atanh(x: f32) -> f32 {
    if x < 1e-3 {
        x + x * x * x / 3.0
    } else {
        0.5 * ln((1.0 + x) / (1.0 - x))
    }
}

/// `tan(φ)` for |φ| < π/2 from the sine alone.
#[inline]
fn tan(phi: f32) -> f32 {
    sin(phi) / sin(phi + core::f32::consts::FRAC_PI_2)
}

impl Spencer {
    /// `dζ/dD = A − β|ζ|ⁿ − γ·ζ·|ζ|ⁿ⁻¹` (≥ 0 within the bound), ζ = z·sgn(Δw).
    #[inline]
    pub(super) fn slope(&self, zeta: f32) -> f32 {
        let p = &self.p;
        let m = abs(zeta);
        let g = match self.shape {
            Shape::One => p.a - p.beta * m - p.gamma * zeta,
            Shape::Two => p.a - p.beta * m * m - p.gamma * zeta * m,
            Shape::General => {
                let mn = powf(m, p.n);
                p.a - p.beta * mn - p.gamma * crate::math::sign(zeta) * mn
            }
        };
        if g > 0.0 {
            g
        } else {
            0.0
        }
    }

    /// Exact (n = 1, 2) or second-order (other n) flow of `dζ/dD = slope(ζ)` over `d ≥ 0`,
    /// clamped to the bound.
    #[inline]
    pub(super) fn flow(&self, zeta: f32, d: f32) -> f32 {
        let z = match self.shape {
            Shape::One => self.flow1(zeta, d),
            Shape::Two => self.flow2(zeta, d),
            Shape::General => self.flow_general(zeta, d),
        };
        crate::math::clamp(z, -self.zmax, self.zmax)
    }

    fn flow2(&self, zeta: f32, d: f32) -> f32 {
        let p = &self.p;
        let mut d = d;
        if zeta < 0.0 {
            // Unloading: dζ/dD = A − (β−γ)ζ².
            let b = p.beta - p.gamma;
            if b > 0.0 {
                let (r, q) = (self.r_un, self.q_un);
                if zeta <= -r {
                    // ζ = −r is a rest point of this branch (only with γ = 0, ζ = −z_max).
                    return zeta;
                }
                let t = tanh(q * d);
                let num = zeta + r * t;
                if num < 0.0 {
                    return r * num / (r + zeta * t);
                }
                let dc = atanh(-zeta / r) / q;
                d = (d - dc).max(0.0);
            } else if b < 0.0 {
                let (r, q) = (self.r_un, self.q_un);
                let phi = atan(zeta / r) + q * d;
                if phi < 0.0 {
                    return r * tan(phi);
                }
                d = phi / q;
            } else {
                let z1 = zeta + p.a * d;
                if z1 < 0.0 {
                    return z1;
                }
                d = z1 / p.a;
            }
            // Continue from ζ = 0 on the loading branch.
            let r = self.zmax;
            return r * tanh(self.q_load * d);
        }
        // Loading: dζ/dD = A − (β+γ)ζ², ζ(∞) = z_max.
        let r = self.zmax;
        let x = self.q_load * d;
        if abs(x) <= 0.25 {
            // tanh = E/(E + 2) with E = e²ˣ − 1, folded into the one division.
            let e = expm1_small(2.0 * x);
            return r * (zeta * (e + 2.0) + r * e) / (r * (e + 2.0) + zeta * e);
        }
        let t = tanh(x);
        r * (zeta + r * t) / (r + zeta * t)
    }

    fn flow1(&self, zeta: f32, d: f32) -> f32 {
        let p = &self.p;
        let mut d = d;
        if zeta < 0.0 {
            // Unloading: dζ/dD = A − (β−γ)|ζ| = A + bζ.
            let b = p.beta - p.gamma;
            let k = p.a + b * zeta;
            let z1 = if k > 0.0 { zeta + k * d * phi1(b * d) } else { zeta };
            if z1 < 0.0 || k.is_nan() || k <= 0.0 {
                return z1;
            }
            let dc = (-zeta / p.a) * ln1p_over(b * zeta / p.a);
            d = (d - dc).max(0.0);
            return self.zmax * -expm1(-self.q_load * d);
        }
        // Loading: dζ/dD = A − (β+γ)ζ.
        zeta - (self.zmax - zeta) * expm1(-self.q_load * d)
    }

    /// General n, in normalised units `q = ζ/z_max`, `s = A·D/z_max`:
    /// - unloading (`q < 0`): `dq/ds = 1 − ρ·|q|ⁿ`, `ρ = (β−γ)/(β+γ) ∈ (−1, 1]`, smooth and
    ///   bounded away from 0; the distance to `q = 0` by two-point Gauss–Legendre, the
    ///   path inside the branch by two RK4 steps;
    /// - loading (`q ≥ 0`): `dq/ds = 1 − qⁿ = (1 − q²)·r(q)` with the saturating factor kept
    ///   exact (`atanh q` grows at rate `r`) and the smooth `r(q) = (1 − qⁿ)/(1 − q²)`
    ///   (1 at q = 0, n/2 at q = 1) frozen at the midpoint, over two halves of `s`.
    fn flow_general(&self, zeta: f32, d: f32) -> f32 {
        let p = &self.p;
        let zm = self.zmax;
        let mut q = zeta / zm;
        let mut s = p.a * d / zm;
        if q < 0.0 {
            let rho = (p.beta - p.gamma) / (p.beta + p.gamma);
            let gu = |q: f32| 1.0 - rho * powf(abs(q), p.n);
            if gu(q) <= 0.0 {
                // Rest point of the unloading branch (only with γ = 0, ζ = −z_max).
                return zeta;
            }
            let (g1, g2) = (0.211_324_87, 0.788_675_1);
            let sc = -q * 0.5 * (1.0 / gu(q * g1) + 1.0 / gu(q * g2));
            if s < sc {
                let h = 0.5 * s;
                for _ in 0..2 {
                    let k1 = gu(q);
                    let k2 = gu(q + 0.5 * h * k1);
                    let k3 = gu(q + 0.5 * h * k2);
                    let k4 = gu(q + h * k3);
                    q += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
                }
                return zm * q.min(0.0);
            }
            s -= sc;
            q = 0.0;
        }
        let ratio = |q: f32| {
            let e = 1.0 - q;
            if e < 1e-3 {
                0.5 * p.n * (1.0 - 0.5 * (p.n - 2.0) * e)
            } else {
                (1.0 - powf(q, p.n)) / (1.0 - q * q)
            }
        };
        let tanh_step = |q: f32, x: f32| {
            let t = tanh(x);
            (q + t) / (1.0 + q * t)
        };
        let h = 0.5 * s;
        for _ in 0..2 {
            let qh = tanh_step(q, 0.5 * h * ratio(q));
            q = tanh_step(q, h * ratio(qh));
        }
        zm * q
    }
}
