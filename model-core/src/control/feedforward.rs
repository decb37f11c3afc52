//! Feed-forward: the input that makes a static map produce a target, by bounded Newton
//! steps (no allocation, fixed iteration count, result always inside `[lo, hi]`).
//!
//! Used for the inverse of the model's static part (`B*` with `T_static(B*) = T_ref`,
//! where `T_static` is the model evaluated at `Ḃ = 0` from its present state) and for the
//! baseline's static current → torque map.
//!
//! The control step's feed-forward is [`Linear`]: the inverse linearised around its
//! operating point by the slow pass (about 1 kHz: one chord step of the operating point
//! towards the latest reference, the static torque and its slope there), applied per
//! sample as an affine map of the reference with one limit.

use super::config::Coeffs;
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
    inverse_of_rise(f(x + h) - f(x), h)
}

/// `h/rise` for a finite `rise` (`±∞` for 0), else 0: [`inverse_slope`] from its
/// difference.
#[inline(always)]
fn inverse_of_rise(rise: f32, h: f32) -> f32 {
    // `rise − rise` is 0 exactly when `rise` is finite (one subtraction and a compare).
    #[allow(clippy::eq_op)]
    if rise - rise == 0.0 {
        h / rise
    } else {
        0.0
    }
}

/// One bounded chord step of `f(x) = target` from `x ∈ [0, hi]` with the reciprocal slope
/// `inv_slope` ([`inverse_slope`], taken now or a little earlier): Newton's method with a
/// lagged derivative, one evaluation of `f` and no division. The step is limited to
/// `±max_step`; a non-finite quotient (an infinite or NaN `f`) leaves `x`. The result is
/// in `[0, hi]` for a finite `x`.
#[inline(always)]
pub fn chord_step<F: Fn(f32) -> f32>(f: F, target: f32, x: f32, inv_slope: f32, hi: f32, max_step: f32) -> f32 {
    chord_from(f(x), target, x, inv_slope, hi, max_step)
}

/// [`chord_step`] with `f(x)` given (`fx`).
#[inline(always)]
fn chord_from(fx: f32, target: f32, x: f32, inv_slope: f32, hi: f32, max_step: f32) -> f32 {
    let q = (target - fx) * inv_slope;
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

/// The feed-forward current as an affine map of the torque reference, valid near its
/// operating point: `i = clamp(i0 + (T − t0)·gain, lo, hi)`. Set by [`Linear::update`] (the
/// slow pass), read every sample by [`Linear::current`] (one multiply-add and one limit,
/// no model evaluation, no division). Default: 0 A for every reference.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Linear {
    /// Operating point: flux density B* (T, in `[0, b_max − h]`), the static torque there
    /// (N·m, finite) and the reciprocal slope `dB/dT` there (T per N·m; 0: no step).
    pub b0: f32,
    pub t0: f32,
    pub inv_slope: f32,
    /// `b0` as a current (A), the slope as A per N·m (finite), and the limits of the map
    /// (A): B within one Newton step (`ff_step`) of `b0`, inside `[0, b_max − h]`, as a
    /// current inside `[0, i_max]`.
    pub i0: f32,
    pub gain: f32,
    pub lo: f32,
    pub hi: f32,
}

impl Linear {
    /// The feed-forward current (A) for torque `t` (N·m, finite): always finite, in
    /// `[lo, hi]`.
    #[inline(always)]
    pub fn current(&self, t: f32) -> f32 {
        clamp(self.i0 + (t - self.t0) * self.gain, self.lo, self.hi)
    }

    /// Move the operating point one chord step (limited to `ff_step`, inside
    /// `[0, ff_hi]`) towards `target` (N·m, finite) with the present reciprocal slope,
    /// i.e. to where the map puts `target`, and take the static torque `f` and its slope
    /// there (forward difference of width `ff_h`). A non-finite `f` there leaves no slope
    /// (the map is then constant); a flat `f` gives the largest finite gain.
    pub fn update<F: Fn(f32) -> f32>(&mut self, f: F, target: f32, k: &Coeffs) {
        let b0 = chord_from(self.t0, target, self.b0, self.inv_slope, k.ff_hi, k.ff_step);
        let t0 = f(b0);
        // `t0 − t0` is 0 exactly when `t0` is finite.
        #[allow(clippy::eq_op)]
        let (t0, inv_slope) =
            if t0 - t0 == 0.0 { (t0, inverse_of_rise(f(b0 + k.ff_h) - t0, k.ff_h)) } else { (0.0, 0.0) };
        let b_lo = if b0 > k.ff_step { b0 - k.ff_step } else { 0.0 };
        let b_hi = if b0 + k.ff_step < k.ff_hi { b0 + k.ff_step } else { k.ff_hi };
        *self = Self {
            b0,
            t0,
            inv_slope,
            i0: b0 * k.amp_per_b,
            // ±∞ (flat) → ±f32::MAX, so that `(t − t0)·gain` is never NaN.
            gain: crate::math::clamp_symmetric(inv_slope * k.amp_per_b, f32::MAX),
            lo: clamp(b_lo * k.amp_per_b, 0.0, k.i_max),
            hi: clamp(b_hi * k.amp_per_b, 0.0, k.i_max),
        };
    }
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
    #[cold]
    #[inline(never)]
    pub fn current(&self, t: f32, i_max: f32) -> f32 {
        invert(|i| self.torque(i), t, 0.5 * i_max, 0.0, i_max, 8, 1e-3 * i_max)
    }
}

#[cfg(test)]
mod tests;
