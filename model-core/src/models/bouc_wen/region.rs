//! Exact integration of one sign region of `w = sgn(ẋ)·z` along the stroke for `n = 1`
//! (exponential) and `n = 2` (Riccati: `tanh`/`tan` forms), stopping where `w` reaches 0
//! (module docs of [`bouc_wen`](super)).

use crate::math::{abs, atan, expm1, sqrt, tan, tanh};

/// Result of integrating one sign region.
pub(super) enum Leg {
    /// Stayed in the region; the final |w|.
    Done(f32),
    /// Reached w = 0 with this much of the leg left.
    Crossed(f32),
}

/// `dv/dξ = p − q·v` from `v0 ≥ 0` over `l`, stopping at `v = 0` (exact).
pub(super) fn region_n1(v0: f32, l: f32, p: f32, q: f32) -> Leg {
    // v(ξ) = v0 + (p − q v0)·φ(ξ), φ(ξ) = (1 − e^{−qξ})/q.
    let phi = |x: f32| if q == 0.0 { x } else { -expm1(-q * x) / q };
    let f0 = p - q * v0;
    if p < 0.0 && f0 < 0.0 {
        let phi_star = v0 / -f0;
        let phi_l = phi(l);
        if phi_l >= phi_star {
            let xi = if q == 0.0 { phi_star } else { -libm::log1pf(-q * phi_star) / q };
            let rem = l - xi;
            return Leg::Crossed(if rem > 0.0 { rem } else { 0.0 });
        }
        let v = v0 + f0 * phi_l;
        return Leg::Done(if v > 0.0 { v } else { 0.0 });
    }
    Leg::Done(v0 + f0 * phi(l))
}

/// The level `s = √|p/q|` and rate `r = √|p·q|` of a region's Riccati solution (n = 2),
/// fixed by the parameters: the same bits as taken in each branch of [`region_n2`] (a
/// quotient's or product's magnitude does not depend on the operands' signs), two square
/// roots and a division fewer per step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Roots {
    s: f32,
    r: f32,
}

impl Roots {
    /// The roots of the region with `p` and `q` (zero when `q = 0`, where they are not used).
    pub(super) fn of(p: f32, q: f32) -> Self {
        if q == 0.0 {
            return Self { s: 0.0, r: 0.0 };
        }
        Self { s: sqrt(abs(p / q)), r: sqrt(abs(p * q)) }
    }
}

/// `dv/dξ = p − q·v²` from `v0 ≥ 0` over `l`, stopping at `v = 0` (exact Riccati);
/// `roots`: [`Roots::of`] `p` and `q`.
pub(super) fn region_n2(v0: f32, l: f32, p: f32, q: f32, roots: Roots) -> Leg {
    let Roots { s, r } = roots;
    if q == 0.0 {
        let v = v0 + p * l;
        if p < 0.0 && v <= 0.0 {
            let rem = l - v0 / -p;
            return Leg::Crossed(if rem > 0.0 { rem } else { 0.0 });
        }
        return Leg::Done(v);
    }
    if p > 0.0 {
        if q > 0.0 {
            // v = s·tanh(rξ + atanh(v0/s)) in Möbius form (valid for v0 > s too).
            let t = tanh(r * l);
            return Leg::Done(s * (v0 + s * t) / (s + v0 * t));
        }
        // p > 0 > q: finite-distance blow-up; outside the validated class.
        return Leg::Done(f32::INFINITY);
    }
    if q > 0.0 {
        // dv/dξ = −(|p| + q v²): v = s·tan(atan(v0/s) − rξ).
        let th = atan(v0 / s);
        let rl = r * l;
        if rl >= th {
            let rem = l - th / r;
            return Leg::Crossed(if rem > 0.0 { rem } else { 0.0 });
        }
        let t = tan(rl);
        let v = s * (v0 - s * t) / (s + v0 * t);
        return Leg::Done(if v > 0.0 { v } else { 0.0 });
    }
    // p < 0, q < 0: dv/dξ = −|q|(s² − v²), v = s·tanh(atanh(v0/s) − rξ) while v0 < s.
    if v0 >= s {
        return Leg::Done(v0);
    }
    let u = v0 / s;
    let t = tanh(r * l);
    if t >= u {
        let rem = l - libm::atanhf(u) / r;
        return Leg::Crossed(if rem > 0.0 { rem } else { 0.0 });
    }
    let v = s * (v0 - s * t) / (s - v0 * t);
    Leg::Done(if v > 0.0 { v } else { 0.0 })
}
