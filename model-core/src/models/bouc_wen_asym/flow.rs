//! The exact flows of z along the path length `σ = |x|/d` in the loading (`u = sgn(ẋ)·w ≥ 0`)
//! and unloading regions, with secant rates about their fixed points (module docs of
//! [`bouc_wen_asym`](super)).

use super::{BoucWenAsym, Order};
use crate::math::{abs, atan, expm1, ln, powf, tan, tanh};

/// Result of the unloading-region flow.
pub(super) enum Fall {
    /// Stayed in the region, at this |z|.
    Stopped(f32),
    /// Reached z = 0 with this much path length left.
    Crossed(f32),
}

/// `−ln(1 − r)` for `r ≤ 1`, accurate for small |r|.
fn neg_ln1m(r: f32) -> f32 {
    if abs(r) < 1e-3 {
        r * (1.0 + r * (0.5 + r * (1.0 / 3.0)))
    } else {
        -ln(1.0 - r)
    }
}

/// `atanh(r)` for `0 ≤ r ≤ 1`.
fn atanh(r: f32) -> f32 {
    if r < 1e-3 {
        r * (1.0 + r * r * (1.0 / 3.0))
    } else {
        0.5 * ln((1.0 + r) / (1.0 - r))
    }
}

impl BoucWenAsym {
    /// Secant rate of the loading flow about z̄.
    #[inline]
    fn lam_rise(&self, u: f32) -> f32 {
        let k = &self.k;
        let dz = u - k.zbar;
        if abs(dz) <= 1e-4 * k.zbar {
            k.lam1_eq
        } else {
            (k.aa - k.c1 * powf(u, self.n)) / dz
        }
    }

    /// Secant rate of the unloading flow about its fixed point e₂.
    #[inline]
    fn lam_fall(&self, v: f32) -> f32 {
        let k = &self.k;
        let dv = v - k.e2;
        if abs(dv) <= 1e-4 * abs(k.e2) {
            k.lam2_eq
        } else {
            (-k.aa + k.c2 * powf(v, self.n)) / dv
        }
    }

    /// Loading region: `du/dσ = |A| − c₁·uⁿ`, `u ≥ 0`, over path length `h`.
    #[inline]
    pub(super) fn rise(&self, u0: f32, h: f32) -> f32 {
        let k = &self.k;
        match k.order {
            Order::One => u0 + (u0 - k.zbar) * expm1(-k.c1 * h),
            Order::Two => {
                let t = tanh(k.om1 * h);
                k.zbar * (u0 + k.zbar * t) / (k.zbar + u0 * t)
            }
            Order::General => {
                let pred = u0 + (u0 - k.zbar) * expm1(self.lam_rise(u0) * h);
                let mid = 0.5 * (u0 + pred);
                let pred = u0 + (u0 - k.zbar) * expm1(self.lam_rise(mid) * h);
                let mid = 0.5 * (u0 + pred);
                u0 + (u0 - k.zbar) * expm1(self.lam_rise(mid) * h)
            }
        }
    }

    /// Unloading region: `dv/dσ = −|A| + c₂·vⁿ`, `v > 0`, until v = 0.
    #[inline]
    pub(super) fn fall(&self, v0: f32, h: f32) -> Fall {
        let k = &self.k;
        let done = |s_star: f32, stop: f32| {
            if s_star <= h {
                Fall::Crossed(h - s_star)
            } else {
                Fall::Stopped(stop.max(0.0))
            }
        };
        if k.c2 == 0.0 {
            return done(v0 / k.aa, v0 - k.aa * h);
        }
        if k.c2 > 0.0 && v0 >= k.e2 {
            // At the unstable fixed point z_run (only reachable through the clamp).
            return Fall::Stopped(v0);
        }
        match k.order {
            Order::One => {
                let s_star = neg_ln1m(v0 / k.e2) / k.c2;
                if s_star <= h {
                    Fall::Crossed(h - s_star)
                } else {
                    Fall::Stopped((v0 + (v0 - k.e2) * expm1(k.c2 * h)).max(0.0))
                }
            }
            Order::Two => {
                let e = abs(k.e2);
                if k.c2 > 0.0 {
                    let s_star = atanh(v0 / e) / k.om2;
                    if s_star <= h {
                        Fall::Crossed(h - s_star)
                    } else {
                        let t = tanh(k.om2 * h);
                        Fall::Stopped((e * (v0 - e * t) / (e - v0 * t)).max(0.0))
                    }
                } else {
                    let th0 = atan(v0 / e);
                    let s_star = th0 / k.om2;
                    if s_star <= h {
                        Fall::Crossed(h - s_star)
                    } else {
                        let th = th0 - k.om2 * h;
                        // tan in f32 (libm's sinf computes in f64: soft-float in the control interrupt).
                        Fall::Stopped((e * tan(th)).max(0.0))
                    }
                }
            }
            Order::General => {
                let s_star = neg_ln1m(v0 / k.e2) / self.lam_fall(0.5 * v0);
                if s_star <= h {
                    return Fall::Crossed(h - s_star);
                }
                let pred = (v0 + (v0 - k.e2) * expm1(self.lam_fall(v0) * h)).max(0.0);
                let mid = 0.5 * (v0 + pred);
                let pred = (v0 + (v0 - k.e2) * expm1(self.lam_fall(mid) * h)).max(0.0);
                let mid = 0.5 * (v0 + pred);
                Fall::Stopped((v0 + (v0 - k.e2) * expm1(self.lam_fall(mid) * h)).max(0.0))
            }
        }
    }
}
