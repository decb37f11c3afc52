#![allow(clippy::unwrap_used, clippy::indexing_slicing, clippy::panic)]
use super::*;

/// Run an estimator over `x(t) = sin(2π f t)` and return the worst errors of ẋ and ẍ
/// against the analytic values after a settling time, each relative to its amplitude,
/// after compensating a pure delay `delay` seconds.
fn sine_errors(p: RateParams, dt: f32, f: f32, delay: f32) -> (f32, f32) {
    let w = 2.0 * core::f32::consts::PI * f;
    let mut s = RateState::default();
    let (mut e1, mut e2) = (0.0f32, 0.0f32);
    for k in 0..(2.0 / dt) as usize {
        let t = k as f32 * dt;
        let (dx, ddx) = p.step(&mut s, (w * t).sin());
        if t > 0.5 {
            let td = t - delay;
            e1 = e1.max((dx - w * (w * td).cos()).abs() / w);
            e2 = e2.max((ddx + w * w * (w * td).sin()).abs() / (w * w));
        }
    }
    (e1, e2)
}

#[test]
fn backward_difference_is_eq13_14() {
    let p = RateParams::backward(0.1).unwrap();
    let mut s = RateState::default();
    assert_eq!(p.step(&mut s, 1.0), (0.0, 0.0));
    let (d1, a1) = p.step(&mut s, 1.5);
    assert!((d1 - 5.0).abs() < 1e-5 && a1 == 0.0);
    let (d2, a2) = p.step(&mut s, 2.5);
    assert!((d2 - 10.0).abs() < 1e-4);
    // eq. 14: (x_k − 2x_{k−1} + x_{k−2}) / T² = (2.5 − 3 + 1) / 0.01 = 50
    assert!((a2 - 50.0).abs() < 1e-3, "{a2}");
}

#[test]
fn estimators_track_a_sine() {
    let dt = 1.0 / 3000.0;
    let b = RateParams::backward(dt).unwrap();
    let (e1, _) = sine_errors(b, dt, 5.0, b.delay_s());
    assert!(e1 < 1e-3, "backward ẋ error {e1}");
    let fl = RateParams::filtered(dt, 200.0).unwrap();
    let (e1, _) = sine_errors(fl, dt, 5.0, fl.delay_s());
    assert!(e1 < 0.01, "filtered ẋ error {e1}");
    // Kalman, seed 002's q = 200 is tuned for their data; a unit sine at 5 Hz has a
    // jerk of ~3e4, so use a q that matches the signal.
    let k = RateParams::kalman(dt, 1e9, 1e-6).unwrap();
    let (e1, e2) = sine_errors(k, dt, 5.0, 0.0);
    assert!(e1 < 0.01 && e2 < 0.05, "kalman errors {e1} {e2}");
}

#[test]
fn kalman_gain_is_a_fixed_point_and_filters_noise() {
    let dt = 1e-3;
    let gain = match RateParams::kalman(dt, 200.0, 0.01).unwrap() {
        RateParams::Kalman { gain, .. } => gain,
        other => panic!("not a Kalman filter: {other:?}"),
    };
    assert!(gain.iter().all(|g| *g > 0.0) && gain[0] < 1.0, "{gain:?}");
    // Constant input with alternating noise: the rate estimate stays far smaller than
    // the backward difference's ±2·noise/dt.
    let p = RateParams::kalman(dt, 200.0, 0.01).unwrap();
    let mut s = RateState::default();
    let mut worst = 0.0f32;
    for k in 0..5000 {
        let (dx, _) = p.step(&mut s, if k % 2 == 0 { 0.01 } else { -0.01 });
        if k > 2000 {
            worst = worst.max(dx.abs());
        }
    }
    assert!(worst < 0.1 * 0.02 / dt, "kalman rate on noise {worst}");
}

#[test]
fn bad_settings_are_rejected() {
    assert!(RateParams::backward(0.0).is_err());
    assert!(RateParams::backward(f32::NAN).is_err());
    assert!(RateParams::filtered(1e-3, 600.0).is_err()); // above Nyquist
    assert!(RateParams::filtered(1e-3, 0.0).is_err());
    assert!(RateParams::kalman(1e-3, -1.0, 0.01).is_err());
    assert!(RateParams::kalman(1e-3, 200.0, f32::INFINITY).is_err());
}
