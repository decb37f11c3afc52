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

/// The slow pass's updates move the operating point to the inverse of the reference;
/// in between, the per-sample map is the static part's tangent there, within its step
/// limit and the current limit, and finite for any finite torque.
#[test]
fn linear_map_tracks_the_inverse_and_stays_bounded() {
    use crate::control::config::Coeffs;
    use crate::control::ControlConfig;
    let m = Algebraic::new(20.0, -0.05, -2.0, 0.8, 1e-4).unwrap();
    let f = |b: f32| static_output(&m, &(), b, 0.0);
    let k = Coeffs::new(&ControlConfig::defaults(1e-4));
    let mut ff = Linear::default();
    assert_eq!(ff.current(5.0), 0.0, "no map before the first update");
    for _ in 0..6 {
        ff.update(f, 6.0, &k);
    }
    let b = ff.current(6.0) / k.amp_per_b;
    assert!((f(b) - 6.0).abs() < 1e-3, "{b}: {}", f(b));
    // Near the operating point, the tangent: second-order error.
    let b1 = ff.current(6.2) / k.amp_per_b;
    assert!((f(b1) - 6.2).abs() < 2e-3, "{b1}: {}", f(b1));
    // Far from it, the step and current limits.
    assert!(ff.current(1e9) <= k.i_max && ff.current(1e9) <= (ff.b0 + k.ff_step) * k.amp_per_b + 1e-6);
    assert!(ff.current(-1e9) >= 0.0 && ff.current(-1e9) >= (ff.b0 - k.ff_step) * k.amp_per_b - 1e-6);
    // A flat map: the largest finite gain, no NaN at the operating point.
    let mut flat = Linear::default();
    flat.update(|_| 2.0, 1.0, &k);
    for t in [2.0f32, 1.0, 3.0, f32::MAX, -f32::MAX] {
        let i = flat.current(t);
        assert!(i.is_finite() && (flat.lo..=flat.hi).contains(&i), "{t}: {i}");
    }
    // A non-finite static part: a constant map.
    let mut bad = ff;
    bad.update(|_| f32::NAN, 6.0, &k);
    assert_eq!((bad.gain, bad.t0), (0.0, 0.0));
    assert_eq!(bad.current(3.0), bad.current(9.0));
}
