use super::*;

#[test]
fn fast_exp_and_tanh_match_libm() {
    let mut worst_exp = 0.0f64;
    let mut worst_tanh = 0.0f64;
    for i in 0..=200_000 {
        let y = 64.0 * i as f32 / 200_000.0;
        let want = (-f64::from(y)).exp();
        // The rounding of t = −y·log₂e adds ~6e-8·y (relative) on top of the series.
        let rel = (f64::from(exp_neg_fast(y)) - want).abs() / want;
        worst_exp = worst_exp.max(rel / (4e-7 + 8e-8 * f64::from(y)));
        let x = -12.0 + 24.0 * i as f32 / 200_000.0;
        worst_tanh = worst_tanh.max((f64::from(tanh_fast(x)) - f64::from(x).tanh()).abs());
    }
    assert!(worst_exp < 1.0, "exp relative error beyond 4e-7 + 8e-8·y: {worst_exp}");
    assert!(worst_tanh < 5e-7, "tanh error {worst_tanh}");
    assert_eq!(tanh_fast(0.0), 0.0);
    assert_eq!(tanh_fast(-30.0), -1.0);
    assert!(tanh_fast(f32::NAN).is_nan());
}

#[test]
fn small_argument_expm1_and_tanh_match_f64() {
    let (mut worst_e, mut worst_t) = (0.0f64, 0.0f64);
    for i in -100_000..=100_000 {
        // Both sides of the switch to libm, and the tiny arguments where cancellation bites.
        let x = 0.8 * i as f32 / 100_000.0;
        for x in [x, x * 1e-4] {
            let want = f64::from(x).exp_m1();
            if want != 0.0 {
                worst_e = worst_e.max(((f64::from(expm1_small(x)) - want) / want).abs());
            }
            let want = f64::from(x).tanh();
            if want != 0.0 {
                worst_t = worst_t.max(((f64::from(tanh_small(x)) - want) / want).abs());
            }
        }
    }
    assert!(worst_e < 2e-7, "expm1 relative error {worst_e}");
    assert!(worst_t < 1.5e-6, "tanh relative error {worst_t}");
    assert!(expm1_small(f32::NAN).is_nan() && tanh_small(f32::NAN).is_nan());
    assert_eq!(tanh_small(0.0), 0.0);
    assert_eq!((tanh_small(20.0), tanh_small(-20.0)), (1.0, -1.0));
}

#[test]
fn symmetric_clamp_limits_and_zeroes_nan() {
    assert_eq!(clamp_symmetric(0.5, 1.0), 0.5);
    assert_eq!(clamp_symmetric(3.0, 1.0), 1.0);
    assert_eq!(clamp_symmetric(-3.0, 1.0), -1.0);
    assert_eq!(clamp_symmetric(f32::NAN, 1.0), 0.0);
    assert_eq!(clamp_symmetric(f32::NEG_INFINITY, 2.0), -2.0);
}

/// Error of an f32 result in units of the last place of the exact value (f64 `tan` is
/// correct to ~1e-16 relative, far below an f32 ulp).
fn ulps(got: f32, want: f64) -> f64 {
    // ulp of the f32 binade holding the exact value: 2^(exponent − 23), at least 2⁻¹⁴⁹.
    let exponent = ((want.abs().to_bits() >> 52) as i32 - 1023).max(-126);
    (f64::from(got) - want).abs() / 2f64.powi(exponent - 23)
}

#[test]
fn tan_is_within_one_ulp_of_f64_tan_on_the_bouc_wen_range() {
    // The Riccati leg's argument: [0, π/2) (every 64th f32 there, and every f32 in the last
    // 2¹⁶ below π/2, where tan grows without bound), and the negated arguments.
    let top = core::f32::consts::FRAC_PI_2.to_bits() - 1;
    assert!(f64::from(f32::from_bits(top)) < std::f64::consts::FRAC_PI_2);
    let bits = (0..top).step_by(64).chain(top - (1 << 16)..=top);
    let (mut worst, mut worst_at, mut libm_apart) = (0.0f64, 0.0f32, 0u32);
    for b in bits {
        let x = f32::from_bits(b);
        for x in [x, -x] {
            let got = tan(x);
            let e = ulps(got, f64::from(x).tan());
            if e > worst {
                (worst, worst_at) = (e, x);
            }
            libm_apart = libm_apart.max(got.to_bits().abs_diff(libm::tanf(x).to_bits()));
        }
    }
    assert!(worst <= 1.0, "tan: {worst} ulp at {worst_at:e}");
    // libm's tanf (an f64 evaluation rounded once) is within an ulp too: the two are equal
    // or neighbours.
    assert!(libm_apart <= 1, "tan and libm's tanf {libm_apart} ulp apart");
}

#[test]
fn tan_is_within_one_ulp_of_f64_tan_up_to_8192_and_nan_beyond() {
    let mut worst = (0.0f64, 0.0f32);
    let mut x = core::f32::consts::FRAC_PI_4;
    while x <= 8192.0 {
        let e = ulps(tan(x), f64::from(x).tan());
        if e > worst.0 {
            worst = (e, x);
        }
        x = f32::from_bits(x.to_bits() + 997);
    }
    assert!(worst.0 <= 1.0, "tan: {} ulp at {:e}", worst.0, worst.1);
    // Multiples of π/2 the reduction must resolve (the f32s nearest k·π/2).
    for k in 1..5000 {
        let x = (f64::from(k) * std::f64::consts::FRAC_PI_2) as f32;
        let e = ulps(tan(x), f64::from(x).tan());
        assert!(e <= 1.0, "tan({x:e}) (k = {k}): {e} ulp");
    }
    assert_eq!(tan(0.0).to_bits(), 0.0f32.to_bits());
    assert_eq!(tan(-0.0).to_bits(), (-0.0f32).to_bits());
    assert_eq!(tan(1e-30), 1e-30);
    for x in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 8192.5, -1e30] {
        assert!(tan(x).is_nan(), "tan({x})");
    }
}
