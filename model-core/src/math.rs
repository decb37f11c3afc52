//! The few transcendental functions the models need, in one place.
//!
//! `libm` is used on every target so that the host replay and the firmware compute the
//! same f32 results. Everything here is total: no function panics on any input.

#[inline(always)]
pub fn exp(x: f32) -> f32 {
    libm::expf(x)
}
#[inline(always)]
pub fn tanh(x: f32) -> f32 {
    libm::tanhf(x)
}
#[inline(always)]
pub fn atan(x: f32) -> f32 {
    libm::atanf(x)
}
#[inline(always)]
pub fn sin(x: f32) -> f32 {
    libm::sinf(x)
}
#[inline(always)]
pub fn sqrt(x: f32) -> f32 {
    libm::sqrtf(x)
}
#[inline(always)]
pub fn powf(x: f32, y: f32) -> f32 {
    libm::powf(x, y)
}
#[inline(always)]
pub fn ln(x: f32) -> f32 {
    libm::logf(x)
}
#[inline(always)]
pub fn expm1(x: f32) -> f32 {
    libm::expm1f(x)
}
/// `|x|` without going through std.
#[inline(always)]
pub fn abs(x: f32) -> f32 {
    libm::fabsf(x)
}
/// Sign with `sign(0) = 0` (the papers' `sign`), NaN maps to 0.
#[inline(always)]
pub fn sign(x: f32) -> f32 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}
/// Clamp that never panics (unlike `f32::clamp` with `lo > hi`); NaN maps to `lo`.
#[inline(always)]
pub fn clamp(x: f32, lo: f32, hi: f32) -> f32 {
    if x > hi {
        hi
    } else if x >= lo {
        x
    } else {
        lo
    }
}
