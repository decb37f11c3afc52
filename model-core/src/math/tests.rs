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
