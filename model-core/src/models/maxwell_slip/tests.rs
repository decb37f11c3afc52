#![allow(clippy::unwrap_used, clippy::indexing_slicing)]
use super::*;

fn kin(x: f32) -> Kin {
    Kin::new(x, 0.0, 0.0, 0.0)
}

/// One elasto-slide element against eq. 23–24 written out with block positions.
#[test]
fn element_matches_eq23_24() {
    let (k, f) = (2.0f32, 1.0f32);
    let m = MaxwellSlip::new(0.0, [k], [f], 0.0, 1e-3).unwrap();
    let xs = [0.0f32, 0.25, 0.5, 1.0, 0.8, 0.5, 0.0, -0.5, -0.25, 0.3];
    let mut s = m.initial_state(&kin(xs[0]));
    // Textbook reference with the block position x_b.
    let mut xb = xs[0];
    let mut xprev = xs[0];
    for &x in &xs {
        let y = m.step(&mut s, &kin(x));
        let trial = k * (x - xb);
        let want = if trial.abs() < f {
            trial
        } else {
            let sg = (x - xprev).signum();
            xb = x - f / k * sg;
            f * sg
        };
        xprev = x;
        assert!((y - want).abs() < 1e-6, "x={x}: {y} vs {want}");
    }
    // Hand values: rising to 1.0 saturates at f; back at 0.5 the spring is relaxed.
    let mut s = m.initial_state(&kin(0.0));
    for (x, w) in [(0.25, 0.5), (1.0, 1.0), (0.5, 0.0), (0.0, -1.0)] {
        let y = m.step(&mut s, &kin(x));
        assert!((y - w).abs() < 1e-6, "x={x}: {y} vs {w}");
    }
}

#[test]
fn sum_offset_linear_term_and_bounds() {
    let m = MaxwellSlip::new(0.1, [1.0, 10.0], [0.5, 0.2], 0.3, 1e-3).unwrap();
    let mut s = m.initial_state(&kin(0.0));
    // x = 0.04: element 1 elastic (0.04 < 0.5/1), element 2 slips at f = 0.2
    // (its deflection limit is 0.2/10 = 0.02): 0.1 + 0.3·0.04 + 0.04 + 0.2
    let y = m.step(&mut s, &kin(0.04));
    assert!((y - (0.1 + 0.012 + 0.04 + 0.2)).abs() < 1e-6, "{y}");
    // x = 0.03: element 2 unloads elastically from +0.02 to +0.01.
    let y = m.step(&mut s, &kin(0.03));
    assert!((y - (0.1 + 0.009 + 0.03 + 0.1)).abs() < 1e-6, "{y}");
    // x = 1e30 then back: deflections never exceed f/k.
    m.step(&mut s, &kin(1e30));
    assert_eq!(s.d, [0.5, 0.02]);
    m.step(&mut s, &kin(-1e30));
    assert_eq!(s.d, [-0.5, -0.02]);
}

/// The loop of an elasto-slide element is clockwise (seed 004 §5): the rising branch
/// (F = +f once sliding) lies above the falling branch (F = −f).
#[test]
fn loop_is_clockwise() {
    let m = MaxwellSlip::new(0.0, [1.0], [0.2], 0.0, 1e-3).unwrap();
    let mut s = m.initial_state(&kin(-1.0));
    let n = 200;
    let mut up = 0.0;
    let mut down = 0.0;
    for cycle in 0..2 {
        for i in 0..=2 * n {
            let x = if i <= n { -1.0 + 2.0 * i as f32 / n as f32 } else { 3.0 - 2.0 * i as f32 / n as f32 };
            let y = m.step(&mut s, &kin(x));
            if cycle == 1 && i == n / 2 {
                up = y;
            }
            if cycle == 1 && i == 3 * n / 2 {
                down = y;
            }
        }
    }
    // Both samples at x = 0.
    assert!(up > down, "up {up} down {down}");
    assert!((up - 0.2).abs() < 1e-6 && (down + 0.2).abs() < 1e-6);
}

#[test]
fn rejects_bad_params() {
    assert!(MaxwellSlip::new(0.0, [0.0], [1.0], 0.0, 1e-3).is_err());
    assert!(MaxwellSlip::new(0.0, [1.0], [-1.0], 0.0, 1e-3).is_err());
    assert!(MaxwellSlip::new(f32::INFINITY, [1.0], [1.0], 0.0, 1e-3).is_err());
    type M = MaxwellSlip<2>;
    assert_eq!(M::PARAM_NAMES, &["w0", "k[2]", "f[2]", "k0"]);
    let v = [0.1, 1.0, 2.0, 0.5, 0.6, 0.3];
    let m = M::from_params(&v, 1e-3).unwrap();
    assert_eq!((m.k, m.f, m.k0), ([1.0, 2.0], [0.5, 0.6], 0.3));
    let mut out = [0.0; 6];
    assert_eq!(m.write_params(&mut out), 6);
    assert_eq!(out, v);
    assert!(M::from_params(&v[..5], 1e-3).is_err());
}
