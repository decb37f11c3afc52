//! Feed-forward: the input that makes a static map produce a target, by bounded Newton
//! steps (no allocation, fixed iteration count, result always inside `[lo, hi]`).
//!
//! Used for the inverse of the model's static part (`B*` with `T_static(B*) = T_ref`,
//! where `T_static` is the model evaluated at `Ḃ = 0` from its present state) and for the
//! baseline's static current → torque map.

use super::pi::clamp;
use crate::{Kin, Model};

/// Solve `f(x) = target` for `x ∈ [lo, hi]` from `x0` with at most `iters` Newton steps,
/// the slope taken by a forward difference of width `h`. Each step is limited to a quarter
/// of the interval; a flat or non-finite slope stops the iteration. Never panics; returns
/// a finite value inside `[lo, hi]` for finite bounds.
pub fn invert<F: Fn(f32) -> f32>(f: F, target: f32, x0: f32, lo: f32, hi: f32, iters: u8, h: f32) -> f32 {
    let max_step = 0.25 * (hi - lo);
    let mut x = clamp(x0, lo, hi);
    for _ in 0..iters {
        let y = f(x);
        let xh = if x + h <= hi { x + h } else { x - h };
        let slope = (f(xh) - y) / (xh - x);
        let err = y - target;
        if !(slope.is_finite() && err.is_finite()) || crate::math::abs(slope) < 1e-12 {
            break;
        }
        let dx = clamp(-err / slope, -max_step, max_step);
        x = clamp(x + dx, lo, hi);
        if crate::math::abs(dx) < 1e-6 * (hi - lo) {
            break;
        }
    }
    x
}

/// The reciprocal slope `h/(f(x + h) − f(x))` of `f` at `x` for [`chord_step`]: `±∞`
/// for a flat `f` (a full step towards the target, as for a rising `f`), 0 when `f` is not
/// finite there (no step).
#[inline(always)]
pub fn inverse_slope<F: Fn(f32) -> f32>(f: F, x: f32, h: f32) -> f32 {
    let den = f(x + h) - f(x);
    // `den − den` is 0 exactly when `den` is finite (one subtraction and a compare).
    #[allow(clippy::eq_op)]
    if den - den == 0.0 {
        h / den
    } else {
        0.0
    }
}

/// One bounded chord step of `f(x) = target` from `x ∈ [0, hi]` with the reciprocal slope
/// `inv_slope` ([`inverse_slope`], taken now or a little earlier): Newton's method with a
/// lagged derivative, one evaluation of `f` and no division. The step is limited to
/// `±max_step`; a non-finite quotient (an infinite or NaN `f`) leaves `x`. The result is
/// in `[0, hi]` for a finite `x`. The per-sample feed-forward: the reference moves little
/// in one period, so one step from the last solution tracks the root.
#[inline(always)]
pub fn chord_step<F: Fn(f32) -> f32>(f: F, target: f32, x: f32, inv_slope: f32, hi: f32, max_step: f32) -> f32 {
    let q = (target - f(x)) * inv_slope;
    // NaN → no step.
    let dx = crate::math::clamp_symmetric(q, max_step);
    clamp(x + dx, 0.0, hi)
}

/// One bounded Newton step: [`chord_step`] with the slope taken at `x` (forward
/// difference of width `h`; the caller keeps `hi + h` inside the domain of `f`).
#[inline(always)]
pub fn newton_step<F: Fn(f32) -> f32>(f: F, target: f32, x: f32, hi: f32, h: f32, max_step: f32) -> f32 {
    chord_step(&f, target, x, inverse_slope(&f, x, h), hi, max_step)
}

/// The model's static part at its present state: output for input `x` with zero rate.
/// Works on a copy of the state; the state itself is not advanced.
#[inline]
pub fn static_output<M: Model>(m: &M, state: &M::State, x: f32, u: f32) -> f32 {
    let mut s = *state;
    m.step(&mut s, &Kin::new(x, 0.0, 0.0, u))
}

/// Static current → torque map of the baseline, `T = a₀ + a₁|i| + a₂i² + a₃|i|³` (N·m, A),
/// fitted on the clutch at a low rate (so it averages the hysteresis branches).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StaticMap {
    pub a: [f32; 4],
}

impl StaticMap {
    /// Torque at current `i`.
    #[inline]
    pub fn torque(&self, i: f32) -> f32 {
        let x = crate::math::abs(i);
        let [a0, a1, a2, a3] = self.a;
        a0 + x * (a1 + x * (a2 + x * a3))
    }

    /// Current in `[0, i_max]` for torque `t`.
    #[inline(never)]
    pub fn current(&self, t: f32, i_max: f32) -> f32 {
        invert(|i| self.torque(i), t, 0.5 * i_max, 0.0, i_max, 8, 1e-3 * i_max)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::models::algebraic::Algebraic;

    #[test]
    fn inverts_the_algebraic_static_part() {
        let m = Algebraic::new(20.0, -0.05, -2.0, 0.8, 1e-4).unwrap();
        for target in [1.0f32, 4.0, 9.0] {
            let b = invert(|b| static_output(&m, &(), b, 0.0), target, 0.2, 0.0, 0.8, 8, 1e-4);
            let t = static_output(&m, &(), b, 0.0);
            assert!((t - target).abs() < 1e-3, "{target}: B {b} gives {t}");
        }
        // Unreachable targets saturate at the bounds.
        assert_eq!(invert(|b| static_output(&m, &(), b, 0.0), 0.0, 0.2, 0.0, 0.8, 8, 1e-4), 0.0);
        let top = invert(|b| static_output(&m, &(), b, 0.0), 1e9, 0.2, 0.0, 0.8, 8, 1e-4);
        assert!((top - 0.8).abs() < 1e-6);
    }

    #[test]
    fn newton_steps_converge_and_stay_in_range() {
        let m = Algebraic::new(20.0, -0.05, -2.0, 0.8, 1e-4).unwrap();
        let f = |b: f32| static_output(&m, &(), b, 0.0);
        let (hi, h) = (0.8f32 - 0.8e-3, 0.8e-3f32);
        let step = |t: f32, x: f32| newton_step(f, t, x, hi, h, 0.2);
        let mut b = 0.0;
        for _ in 0..8 {
            b = step(6.0, b);
        }
        assert!((f(b) - 6.0).abs() < 1e-3, "{b}: {}", f(b));
        assert_eq!(step(-5.0, 0.0), 0.0);
        assert!((step(1e9, hi) - hi).abs() < 1e-6);
        assert!((step(1e9, 0.1) - 0.3).abs() < 1e-6, "a step is at most max_step");
        assert_eq!(step(f32::NAN, 0.3), 0.3);
        assert_eq!(newton_step(|_| f32::NAN, 1.0, 0.3, hi, h, 0.2), 0.3);
        assert!((newton_step(|_| 2.0, 1.0, 0.3, hi, h, 0.2) - 0.1).abs() < 1e-6, "flat: towards the target");
        assert_eq!(newton_step(|_| 1.0, 1.0, 0.3, hi, h, 0.2), 0.3, "flat at the target");
        let inf = |b: f32| if b > 0.5 { f32::INFINITY } else { b };
        assert_eq!(newton_step(inf, 1.0, 0.55, hi, 0.1, 0.2), 0.55);
        // A lagged slope still converges (chord method).
        let inv = inverse_slope(f, 0.1, h);
        let mut b = 0.1;
        for _ in 0..30 {
            b = chord_step(f, 6.0, b, inv, hi, 0.2);
        }
        assert!((f(b) - 6.0).abs() < 1e-3, "{b}: {}", f(b));
        assert_eq!(chord_step(f, 6.0, 0.2, 0.0, hi, 0.2), 0.2, "no slope, no step");
        assert_eq!(inverse_slope(inf, 0.45, 0.1), 0.0);
    }

    #[test]
    fn static_map_round_trip_and_nan() {
        let map = StaticMap { a: [0.5, 3.0, 0.4, -0.05] };
        let i = map.current(6.0, 3.5);
        assert!((map.torque(i) - 6.0).abs() < 1e-3, "{i}");
        let x = map.current(f32::NAN, 3.5);
        assert!(x.is_finite() && (0.0..=3.5).contains(&x));
        let bad = invert(|_| f32::NAN, 1.0, 0.3, 0.0, 1.0, 8, 1e-3);
        assert!((bad - 0.3).abs() < 1e-6);
    }
}
