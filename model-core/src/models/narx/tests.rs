#![allow(clippy::unwrap_used, clippy::indexing_slicing)]
use super::*;
use std::vec::Vec;

fn sg(s: f64) -> f64 {
    1.0 / (1.0 + (-s).exp())
}

fn small() -> Narx<2> {
    Narx::<2>::new(
        (1.0, 2.0, 0.5, 4.0),
        [0.6, 0.3, -0.2, 0.1, 0.05, -0.05, 0.02],
        [[0.1, 0.2, 0.3, -0.1, 0.0, 0.5, -0.4], [-0.3, 0.1, 0.0, 0.2, 0.2, -0.1, 0.3]],
        [0.1, -0.2],
        [1.5, -0.7],
        0.05,
        (-100.0, 100.0),
        1e-3,
    )
    .unwrap()
}

/// f64 re-implementation of eq. 18–19 with the same normalisation.
fn reference(m: &Narx<2>, u: &[f64], y0: f64, u0: f64) -> Vec<f64> {
    let f = |v: f32| f64::from(v);
    let mut hist = std::vec![u0; 5];
    let mut y = y0;
    let mut out = Vec::new();
    for &ut in u {
        let mut r = std::vec![(y - f(m.y_mean)) / f(m.y_scale), (ut - f(m.u_mean)) / f(m.u_scale)];
        for h in &hist {
            r.push((h - f(m.u_mean)) / f(m.u_scale));
        }
        let mut yn: f64 = m.lin.iter().zip(&r).map(|(a, b)| f(*a) * b).sum::<f64>() + f(m.offset);
        for j in 0..2 {
            let s: f64 = m.hid_w[j].iter().zip(&r).map(|(a, b)| f(*a) * b).sum::<f64>() + f(m.hid_b[j]);
            yn += f(m.out_a[j]) * sg(s);
        }
        y = (f(m.y_mean) + f(m.y_scale) * yn).clamp(f(m.y_min), f(m.y_max));
        hist.insert(0, ut);
        hist.pop();
        out.push(y);
    }
    out
}

#[test]
fn matches_eq18_19() {
    let m = small();
    let mut s = State { u: [0.0; 5], y: 0.0 };
    let u: Vec<f64> = (0..50).map(|i| (i as f64 * 0.3).sin() * 2.0 + 1.0).collect();
    let want = reference(&m, &u, 0.0, 0.0);
    for (ut, w) in u.iter().zip(&want) {
        let y = m.step(&mut s, &Kin::new(*ut as f32, 0.0, 0.0, 0.0));
        assert!((f64::from(y) - w).abs() < 1e-4 * (1.0 + w.abs()), "{y} vs {w}");
    }
}

#[test]
fn feedback_clamped() {
    // W₁ = 3 makes the open recursion explode; the clamp keeps it in range.
    let mut m = small();
    m.lin[0] = 3.0;
    let m = Narx::<2>::new(
        (m.u_mean, m.u_scale, m.y_mean, m.y_scale),
        m.lin,
        m.hid_w,
        m.hid_b,
        m.out_a,
        m.offset,
        (-20.0, 30.0),
        1e-3,
    )
    .unwrap();
    let mut s = m.initial_state(&Kin::new(1.0, 0.0, 0.0, 0.0));
    let mut hit = false;
    for i in 0..500 {
        let y = m.step(&mut s, &Kin::new((i as f32 * 0.1).sin(), 0.0, 0.0, 0.0));
        assert!((-20.0..=30.0).contains(&y));
        hit |= y == 30.0 || y == -20.0;
    }
    assert!(hit, "the recursion should have reached the clamp");
    for u in [1e30f32, -1e30, 3e38] {
        let y = m.step(&mut s, &Kin::new(u, 0.0, 0.0, 0.0));
        assert!(y.is_finite() && s.is_finite());
    }
}

#[test]
fn steady_start() {
    let m = small();
    let mut s = m.initial_state(&Kin::new(0.7, 0.0, 0.0, 0.0));
    let y0 = s.y;
    for _ in 0..5 {
        let y = m.step(&mut s, &Kin::new(0.7, 0.0, 0.0, 0.0));
        assert!((y - y0).abs() < 1e-4 * (1.0 + y0.abs()), "{y} vs {y0}");
    }
}

#[test]
fn steady_start_with_a_slow_feedback() {
    // W₁ = 0.9995: iterating the map 32 times would leave the start far from steady.
    let m = small();
    let m = Narx::<2>::new(
        (m.u_mean, m.u_scale, m.y_mean, m.y_scale),
        [0.9995, 0.3, -0.2, 0.1, 0.05, -0.05, 0.02],
        m.hid_w,
        m.hid_b,
        m.out_a,
        0.01,
        (-1.0e5, 1.0e5),
        1e-3,
    )
    .unwrap();
    let k = Kin::new(0.7, 0.0, 0.0, 0.0);
    let mut s = m.initial_state(&k);
    let y0 = s.y;
    // An interior fixed point, far from y_mean.
    assert!(y0.abs() > 100.0 && y0.abs() < 0.5e5, "{y0}");
    for _ in 0..200 {
        let y = m.step(&mut s, &k);
        assert!((y - y0).abs() < 1e-3 * (1.0 + y0.abs()), "{y} vs {y0}");
    }
}

#[test]
fn names_and_round_trip() {
    assert_eq!(Registered::N_PARAMS, 86);
    assert_eq!(Seed000::N_PARAMS, 653);
    let total = |names: &[&str]| -> usize {
        names
            .iter()
            .map(|n| n.split_once('[').map_or(1, |(_, r)| r.trim_end_matches(']').parse::<usize>().unwrap()))
            .sum()
    };
    assert_eq!(total(Registered::PARAM_NAMES), Registered::N_PARAMS);
    assert_eq!(total(Seed000::PARAM_NAMES), Seed000::N_PARAMS);
    assert!(Seed000::PARAM_NAMES.contains(&"hid_w[497]"));
    assert!(Registered::PARAM_NAMES.contains(&"hid_w[56]"));
    let m = small();
    let mut out = [0.0f32; 32];
    assert_eq!(m.write_params(&mut out), 32);
    let back = Narx::<2>::from_params(&out, 1e-3).unwrap();
    assert_eq!(back, m);
    let mut bad = out;
    bad[1] = 0.0; // u_scale
    assert!(Narx::<2>::from_params(&bad, 1e-3).is_err());
    let mut bad = out;
    bad[31] = -200.0; // y_max < y_min
    assert!(Narx::<2>::from_params(&bad, 1e-3).is_err());
    assert!(Narx::<2>::from_params(&out[..31], 1e-3).is_err());
}
