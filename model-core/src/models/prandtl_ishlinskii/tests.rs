#![allow(clippy::unwrap_used, clippy::indexing_slicing, clippy::expect_used)]
use super::*;

fn kin(x: f32) -> Kin {
    Kin::new(x, 0.0, 0.0, 0.0)
}

#[test]
fn names_and_count() {
    type M = PrandtlIshlinskii<10>;
    assert_eq!(M::PARAM_NAMES, &["p0", "m0", "r[10]", "p[10]"]);
    assert_eq!(M::N_PARAMS, 22);
    assert_eq!(PrandtlIshlinskii::<3>::PARAM_NAMES, &["p0", "m0", "r[3]", "p[3]"]);
}

/// Textbook play operator: backlash of half-width r.
#[test]
fn play_operator_textbook() {
    let r = 0.25;
    let mut z = 0.0;
    // Rising from 0: output stays until x − r exceeds it.
    let xs = [0.0, 0.1, 0.25, 0.5, 1.0, 0.8, 0.5, 0.4, 0.0, -0.2];
    let want = [0.0, 0.0, 0.0, 0.25, 0.75, 0.75, 0.75, 0.65, 0.25, 0.05];
    for (x, w) in xs.iter().zip(want) {
        z = play(*x, r, z);
        assert!((z - w).abs() < 1e-6, "x={x}: {z} vs {w}");
    }
}

/// Eq. 15 by hand for two operators.
#[test]
fn matches_eq15_by_hand() {
    let m = PrandtlIshlinskii::new(0.5, 0.0, [0.1, 0.3], [2.0, 1.0], 1e-3).unwrap();
    let mut s = m.initial_state(&kin(0.0));
    assert_eq!(s.z, [0.0, 0.0]);
    // x = 0.5: plays 0.4 and 0.2 → 0.25 + 0.8 + 0.2
    let y = m.step(&mut s, &kin(0.5));
    assert!((y - (0.25 + 2.0 * 0.4 + 0.2)).abs() < 1e-6);
    // x = 0.35: play 1 holds 0.4 (0.35+0.1 ≥ 0.4), play 2 holds 0.2
    let y = m.step(&mut s, &kin(0.35));
    assert!((y - (0.175 + 0.8 + 0.2)).abs() < 1e-6);
    // x = 0.0: play 1 → 0.1, play 2 → 0.2 (0.0 + 0.3 ≥ 0.2)
    let y = m.step(&mut s, &kin(0.0));
    assert!((y - (0.0 + 0.2 + 0.2)).abs() < 1e-6, "{y}");
}

#[test]
fn initial_condition_eq11() {
    let m = PrandtlIshlinskii::new(0.3, 0.1062, [0.05, 0.5], [1.0, 1.0], 1e-3).unwrap();
    let s = m.initial_state(&kin(0.8));
    // max(0.8 − 0.05, min(0.85, 0.1062)) = 0.75; max(0.3, min(1.3, 0.1062)) = 0.3
    assert!((s.z[0] - 0.75).abs() < 1e-6 && (s.z[1] - 0.3).abs() < 1e-6, "{:?}", s.z);
}

/// For a symmetric periodic input the CPI loop is point-symmetric about its centre:
/// half a period later the input is mirrored and so is the output.
#[test]
fn loop_is_point_symmetric() {
    // Seed 004 Table A8 (CPI, 10 operators).
    let r = [0.8438, 0.6037, 0.0314, 0.0234, 0.0176, 0.0215, 0.0156, 0.0826, 0.0805, 0.0001];
    let p = [0.0006, 0.0180, 0.0430, 0.0035, 0.0156, 0.5756, 0.1777, 0.6034, 0.0163, 0.0156];
    let m = PrandtlIshlinskii::new(0.0610, 0.0862, r, p, 1e-3).unwrap();
    let n = 400usize;
    let c = 0.5f32;
    let amp = 0.5f32;
    let x = |i: usize| c + amp * (2.0 * core::f32::consts::PI * (i % n) as f32 / n as f32).sin();
    let mut s = m.initial_state(&kin(x(0)));
    let mut ys = Vec::new();
    for i in 0..4 * n {
        ys.push(m.step(&mut s, &kin(x(i))));
    }
    let last = &ys[3 * n..];
    let yc = last.iter().sum::<f32>() / n as f32;
    let range = last.iter().cloned().fold(f32::MIN, f32::max) - last.iter().cloned().fold(f32::MAX, f32::min);
    let asym = asymmetry_index(last, yc, range);
    assert!(asym < 1e-3, "CPI loop asymmetry {asym}");
    // A real loop: at the centre input the rising and falling outputs differ.
    let width = (last[0] - last[n / 2]).abs();
    assert!(width > 0.05 * range, "loop width {width} of range {range}");
    // Control: the index does see an offset branch (shift the falling half).
    let mut skewed = last.to_vec();
    for v in &mut skewed[n / 2..] {
        *v += 0.05 * range;
    }
    assert!(asymmetry_index(&skewed, yc, range) > 0.01);
}

/// max_t |y(t) + y(t + T/2) − 2·ȳ| / range over one period of `n` samples.
pub(crate) fn asymmetry_index(y: &[f32], yc: f32, range: f32) -> f32 {
    let n = y.len();
    (0..n / 2).map(|i| (y[i] + y[i + n / 2] - 2.0 * yc).abs()).fold(0.0, f32::max) / range
}

#[test]
fn inverse_coefficients_by_hand() {
    // p0 = 1, (r, p) = (0.1, 1), (0.3, 2) → P = 1, 2, 4.
    let m = PrandtlIshlinskii::new(1.0, 0.0, [0.3, 0.1], [2.0, 1.0], 1e-3).unwrap();
    let inv = m.inverse().unwrap();
    assert!((inv.q0 - 1.0).abs() < 1e-7);
    // r̂₁ = 1·0.1 + 1·0 = 0.1; r̂₂ = 1·0.3 + 1·(0.3 − 0.1) + 2·0 = 0.5
    assert!((inv.r[0] - 0.1).abs() < 1e-6 && (inv.r[1] - 0.5).abs() < 1e-6, "{:?}", inv.r);
    // p̂₁ = −1/(2·1), p̂₂ = −2/(4·2)
    assert!((inv.q[0] + 0.5).abs() < 1e-6 && (inv.q[1] + 0.25).abs() < 1e-6, "{:?}", inv.q);
    assert!(PrandtlIshlinskii::new(0.0, 0.0, [0.3], [2.0], 1e-3).unwrap().inverse().is_err());
}

/// inverse(model(x)) = x on major and minor loops, from a non-relaxed start.
#[test]
fn inverse_round_trip() {
    // Seed 004 Table A7's radii (unsorted, one zero) with non-degenerate weights, and
    // a set with repeated radii.
    let a7 = PrandtlIshlinskii::new(
        0.3223,
        0.1062,
        [0.7709, 0.0455, 0.9998, 0.0, 0.7509],
        [0.2, 0.6034, 0.1, 0.3, 0.05],
        1e-3,
    );
    let ties = PrandtlIshlinskii::new(0.1, -0.2, [0.2, 0.05, 0.2, 0.05, 0.4], [0.5, 0.2, 0.3, 0.1, 1.0], 1e-3);
    for m in [a7.unwrap(), ties.unwrap()] {
        round_trip(&m);
    }
}

fn round_trip(m: &PrandtlIshlinskii<5>) {
    let inv = m.inverse().unwrap();
    let x = |i: usize| {
        let t = i as f32 / 500.0;
        0.5 + 0.45 * (6.0 * t).sin() + 0.2 * (17.0 * t).cos() * (1.3 * t).sin()
    };
    let mut s = m.initial_state(&kin(x(0)));
    let mut si = inv.state_from(&s);
    let mut worst = 0.0f32;
    for i in 0..5000 {
        let y = m.step(&mut s, &kin(x(i)));
        let xh = inv.step(&mut si, y);
        worst = worst.max((xh - x(i)).abs());
    }
    assert!(worst < 2e-5, "round-trip error {worst}");
    // And the reverse composition: model(inverse(y)) = y.
    let mut s = m.initial_state(&kin(0.0));
    let mut si = inv.state_from(&s);
    let mut worst = 0.0f32;
    for i in 0..3000 {
        let yd = 0.2 + 0.15 * (i as f32 / 90.0).sin();
        let xc = inv.step(&mut si, yd);
        let y = m.step(&mut s, &kin(xc));
        worst = worst.max((y - yd).abs());
    }
    assert!(worst < 2e-5, "model(inverse) error {worst}");
}

#[test]
fn rejects_bad_params() {
    assert!(PrandtlIshlinskii::new(0.1, 0.0, [-0.1], [1.0], 1e-3).is_err());
    assert!(PrandtlIshlinskii::new(0.1, 0.0, [0.1], [-1.0], 1e-3).is_err());
    assert!(PrandtlIshlinskii::new(-0.1, 0.0, [0.1], [1.0], 1e-3).is_err());
    assert!(PrandtlIshlinskii::new(0.1, f32::NAN, [0.1], [1.0], 1e-3).is_err());
    assert!(PrandtlIshlinskii::<0>::new(0.1, 0.0, [], [], 1e-3).is_err());
    assert!(PrandtlIshlinskii::<2>::from_params(&[0.1, 0.0, 0.1, 0.2, 1.0], 1e-3).is_err());
    let m = PrandtlIshlinskii::<2>::from_params(&[0.1, 0.0, 0.1, 0.2, 1.0, 2.0], 1e-3).unwrap();
    let mut out = [0.0; 6];
    assert_eq!(m.write_params(&mut out), 6);
    assert_eq!(out, [0.1, 0.0, 0.1, 0.2, 1.0, 2.0]);
}
