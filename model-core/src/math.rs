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
/// `tan(x)` in f32 arithmetic only (libm's `tanf` evaluates in f64: soft-float calls on the
/// Cortex-M4F, where this sits in the control interrupt). Within 1 ulp of the exact value for
/// `|x| ≤ 8192` (the Bouc–Wen Riccati leg calls it on `[0, π/2)`; `math/tests.rs` checks
/// that range against f64 `tan`); NaN for NaN, ±∞ and `|x| > 8192`.
///
/// Method (Cody–Waite, as Cephes' `tanf`, in double-f32 where it matters): `j` = the
/// nearest integer to `x·2/π`, `y = x − j·π/2` with π/2 in four f32 parts (the first two
/// products and differences are exact for `|x| ≤ 8192`, the third is kept as a hi/lo pair),
/// `tan(y)` on `|y| ≤ π/4` by `y + y³/3 + y⁵·h(y²)` ([`TAN_H`]) carried as hi + lo with the
/// reduction's low part, and for odd `j`
/// `−1/tan(y)` with one Newton correction of the reciprocal (Dekker's exact product).
pub fn tan(x: f32) -> f32 {
    let a = abs(x);
    if a < TAN_TINY {
        // x²/3 < 2⁻²⁴/3: tan(x) rounds to x (±0 and subnormals included).
        return x;
    }
    if a <= core::f32::consts::FRAC_PI_4 {
        let (t, t_lo) = tan_kernel(x, 0.0);
        return t + t_lo;
    }
    if a.is_nan() || a > TAN_MAX {
        return f32::NAN;
    }
    // 1.5·2²³: adding it rounds to an integer (a·2/π ≤ 5216 here).
    const MAGIC: f32 = 12_582_912.0;
    let j = (a * core::f32::consts::FRAC_2_PI + MAGIC) - MAGIC;
    // PIO2_1 has 8 significant bits, PIO2_2 11, j ≤ 5216 < 2¹³: both products are exact and
    // so are both differences (multiples of 2⁻²⁴ resp. ulp(a) below 1 resp. 4).
    let b = (a - j * PIO2_1) - j * PIO2_2;
    let (p, p_lo) = two_prod(j, PIO2_3);
    let (y, y_lo) = two_sum(b, -p);
    let (t, t_lo) = tan_kernel(y, y_lo - p_lo - j * PIO2_4);
    // j is a small non-negative integer; `as` cannot fail.
    let t = if (j as u32) & 1 == 1 { -recip(t, t_lo) } else { t + t_lo };
    // tan is odd; the sign of t is that of tan(|x|).
    if x < 0.0 {
        -t
    } else {
        t
    }
}

/// Below this `|x|` (2⁻¹²) [`tan`] returns x.
const TAN_TINY: f32 = 1.0 / 4096.0;
/// Beyond this `|x|` [`tan`] returns NaN (the reduction would need more parts of π/2).
const TAN_MAX: f32 = 8192.0;
/// π/2 = PIO2_1 + PIO2_2 + PIO2_3 + PIO2_4 + O(1e-23): 8 and 11 significant bits, then
/// two f32 roundings of the rest.
const PIO2_1: f32 = 1.570_312_5;
const PIO2_2: f32 = 0.000_483_751_3;
const PIO2_3: f32 = 7.549_79e-8;
const PIO2_4: f32 = -1.715_124_5e-15;
/// `h(w) = ((tan √w/√w − 1)/w − 1/3)/w` on `[0, 1.001·(π/4)²]`, Chebyshev fit of degree 6
/// (mpmath `chebyfit`; absolute error 3.5e-9, 1.1e-9 in `tan`), constant term first.
const TAN_H: [f32; 7] =
    [0.133_333_34, 0.053_967_837, 0.021_880_176, 0.008_762_07, 0.004_039_282_4, 0.000_477_546_68, 0.001_559_253_7];

/// `tan(y + y_lo)` for `|y| ≤ π/4` (a little beyond is harmless), `|y_lo| ≤ ulp(y)`, as
/// an unevaluated sum hi + lo (`|lo| ≤ ulp(hi)`): `y + y³/3 + y⁵·h(y²)`, with `y³` exact
/// to f32² and `y³/3` correctly rounded, so that the rounding errors left are those of
/// the `y⁵` term (≤ 6 % of the result).
#[inline(always)]
fn tan_kernel(y: f32, y_lo: f32) -> (f32, f32) {
    let [h0, h1, h2, h3, h4, h5, h6] = TAN_H;
    let (z, z_lo) = two_prod(y, y);
    let (w, w_lo) = two_prod(y, z);
    let w_lo = w_lo + y * z_lo;
    let c1 = w / 3.0;
    let h = h0 + z * (h1 + z * (h2 + z * (h3 + z * (h4 + z * (h5 + z * h6)))));
    let c2 = (w * z) * h;
    // |y³/3| < |y| with the same sign: y − s is exact (Fast2Sum).
    let s = y + c1;
    let lo = ((y - s) + c1) + (c2 + (w_lo / 3.0 + y_lo * (1.0 + s * s)));
    let hi = s + lo;
    (hi, (s - hi) + lo)
}

/// `1/(hi + lo)` for `|lo| ≤ ulp(hi)`, `hi` ≠ 0 and not near the f32 limits: `q = 1/hi`
/// corrected by its exact residual `1 − q·hi` and by `lo`.
#[inline(always)]
fn recip(hi: f32, lo: f32) -> f32 {
    let q = 1.0 / hi;
    let (p, p_lo) = two_prod(q, hi);
    // p is within an ulp of 1: 1 − p is exact (Sterbenz).
    let e = (1.0 - p) - p_lo;
    q + q * (e - q * lo)
}

/// `a + b = s + e` exactly (Knuth's TwoSum; no ordering assumption).
#[inline(always)]
fn two_sum(a: f32, b: f32) -> (f32, f32) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// `a·b = p + e` exactly without FMA (Dekker with Veltkamp's split by 2¹² + 1), barring
/// overflow and underflow.
#[inline(always)]
fn two_prod(a: f32, b: f32) -> (f32, f32) {
    let split = |v: f32| {
        let c = 4097.0 * v;
        let hi = c - (c - v);
        (hi, v - hi)
    };
    let p = a * b;
    let (ah, al) = split(a);
    let (bh, bl) = split(b);
    (p, ((ah * bh - p) + ah * bl + al * bh) + al * bl)
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
