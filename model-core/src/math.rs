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
/// `e^{−y}` for `0 ≤ y ≤ 64` without libm (the hot paths of the stateless models): `2^t`
/// with `t = −y·log₂e` split into a nearest integer n and `f ∈ [−½, ½]`, `2^f = e^{f·ln 2}`
/// by its Taylor series to the 6th power (relative error ≤ 4e-7 + 8e-8·y, the second
/// term from rounding t), and n added to the
/// exponent bits. Outside `[0, 64]` the result is meaningless; callers bound y.
#[inline(always)]
pub fn exp_neg_fast(y: f32) -> f32 {
    // 1.5·2²³: adding it rounds to an integer held in the low mantissa bits.
    const MAGIC: f32 = 12_582_912.0;
    let t = y * -core::f32::consts::LOG2_E;
    let r = t + MAGIC;
    let f = t - (r - MAGIC);
    let g = f * core::f32::consts::LN_2;
    let p = 1.0 + g * (1.0 + g * (0.5 + g * (1.0 / 6.0 + g * (1.0 / 24.0 + g * (1.0 / 120.0 + g * (1.0 / 720.0))))));
    // r's bits are 0x4B40_0000 + n; shifted left by 23 the constant part vanishes (its low 9
    // bits are zero), leaving n·2²³ (two's complement): the exponent increment.
    f32::from_bits(p.to_bits().wrapping_add(r.to_bits() << 23))
}

/// `tanh(x)` from [`exp_neg_fast`]: `(1 − e^{−2|x|})/(1 + e^{−2|x|})` with the sign of x;
/// ±1 for |x| ≥ 9 (where f32 tanh is ±1). Absolute error ≤ 5e-7 against f64 tanh;
/// NaN stays NaN.
#[inline(always)]
pub fn tanh_fast(x: f32) -> f32 {
    let a = libm::fabsf(x);
    let t = if a < 9.0 {
        let e = exp_neg_fast(2.0 * a);
        (1.0 - e) / (1.0 + e)
    } else if a >= 9.0 {
        1.0
    } else {
        return x;
    };
    libm::copysignf(t, x)
}

/// `eˣ − 1` without range reduction for `|x| ≤ 1/2` (its Taylor series to the 8th power,
/// relative error ≤ 1e-8 before rounding), libm's `expm1f` elsewhere. The hot paths of the
/// flow-based models call it with small arguments almost always.
#[inline(always)]
pub fn expm1_small(x: f32) -> f32 {
    if libm::fabsf(x) <= 0.5 {
        const C: [f32; 7] = [1.0 / 2.0, 1.0 / 6.0, 1.0 / 24.0, 1.0 / 120.0, 1.0 / 720.0, 1.0 / 5040.0, 1.0 / 40320.0];
        let [c2, c3, c4, c5, c6, c7, c8] = C;
        // Estrin-style pairing keeps the dependency chain short.
        let x2 = x * x;
        let hi = (c5 + x * c6) + x2 * (c7 + x * c8);
        let lo = (c2 + x * c3) + x2 * c4;
        x + x2 * (lo + x2 * x * hi)
    } else {
        libm::expm1f(x)
    }
}

/// `tanh(x)` without libm: through [`expm1_small`] for `|x| ≤ 1/4` (`E/(E + 2)`,
/// `E = e²ˣ − 1`, relative error ≤ 2e-7, no cancellation as x → 0), [`tanh_fast`] beyond
/// (relative error ≤ 1.5e-6 there).
#[inline(always)]
pub fn tanh_small(x: f32) -> f32 {
    if libm::fabsf(x) <= 0.25 {
        let e = expm1_small(2.0 * x);
        e / (e + 2.0)
    } else {
        tanh_fast(x)
    }
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

/// `x` limited to `[−lim, lim]` (`lim ≥ 0`), NaN → 0: compares only, no libm. Inside the
/// limits (the usual case) it costs one `|x|` and one compare.
#[inline(always)]
pub fn clamp_symmetric(x: f32, lim: f32) -> f32 {
    if abs(x) <= lim {
        x
    } else {
        limit_sign(x, lim)
    }
}

/// `±lim` with the sign of `x` (`x` beyond `±lim`), 0 for NaN: the out-of-range branch of
/// [`clamp_symmetric`].
#[inline(always)]
pub fn limit_sign(x: f32, lim: f32) -> f32 {
    if x > 0.0 {
        lim
    } else if x < 0.0 {
        -lim
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests;
