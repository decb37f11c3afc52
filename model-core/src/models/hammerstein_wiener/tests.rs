#![allow(clippy::unwrap_used, clippy::indexing_slicing)]
use super::*;
use std::vec::Vec;

fn identity<const N: usize>() -> SigmoidNet<N> {
    SigmoidNet { a: [0.0; N], w: [0.0; N], b: [0.0; N], lin: 1.0, d: 0.0 }
}

/// Monic polynomial coefficients a₁..a₅ from roots (real or conjugate pairs).
fn poly_from_roots(roots: &[(f64, f64)]) -> [f32; 5] {
    // complex multiply out (z − r)
    let mut c: Vec<(f64, f64)> = std::vec![(1.0, 0.0)];
    for &(re, im) in roots {
        let mut n = std::vec![(0.0, 0.0); c.len() + 1];
        for (i, &(a, b)) in c.iter().enumerate() {
            n[i].0 += a;
            n[i].1 += b;
            n[i + 1].0 -= a * re - b * im;
            n[i + 1].1 -= a * im + b * re;
        }
        c = n;
    }
    let mut out = [0.0f32; 5];
    for i in 0..5 {
        out[i] = c[i + 1].0 as f32;
    }
    out
}

#[test]
fn schur_matches_roots() {
    let stable = [(0.5, 0.0), (-0.3, 0.0), (0.2, 0.4), (0.2, -0.4), (0.95, 0.0)];
    assert!(schur_stable(&poly_from_roots(&stable)));
    let unstable = [(0.5, 0.0), (-0.3, 0.0), (0.2, 0.99), (0.2, -0.99), (0.9, 0.0)];
    assert!(!schur_stable(&poly_from_roots(&unstable)));
    assert!(!schur_stable(&poly_from_roots(&[(1.05, 0.0), (0.0, 0.0), (0.0, 0.0), (0.1, 0.0), (0.2, 0.0)])));
    assert!(!schur_stable(&poly_from_roots(&[(-1.0, 0.0), (0.0, 0.0), (0.0, 0.0), (0.1, 0.0), (0.2, 0.0)])));
    assert!(schur_stable(&[0.0; 5]));
    // pseudo-random roots: classification must match max |root| < 1
    let mut seed = 12345u64;
    let mut rnd = || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    };
    for _ in 0..2000 {
        let scale = 1.3;
        let (r1, r2, re, im, r5) = (rnd() * scale, rnd() * scale, rnd() * scale, rnd() * scale, rnd() * scale);
        let roots = [(r1, 0.0), (r2, 0.0), (re, im), (re, -im), (r5, 0.0)];
        let maxmod = roots.iter().map(|(a, b)| (a * a + b * b).sqrt()).fold(0.0, f64::max);
        if (maxmod - 1.0).abs() < 1e-3 {
            continue;
        }
        assert_eq!(schur_stable(&poly_from_roots(&roots)), maxmod < 1.0, "{roots:?}");
    }
}

#[test]
fn linear_block_difference_equation() {
    // Identity nonlinearities: output = v, compare with the difference equation by hand.
    let f = poly_from_roots(&[(0.5, 0.0), (-0.2, 0.0), (0.3, 0.3), (0.3, -0.3), (0.1, 0.0)]);
    let b = [0.4f32, -0.1, 0.25];
    let m = HammersteinWiener::<1, 1>::new(identity(), b, f, identity(), -1e6, 1e6, 1e-3).unwrap();
    let mut s = State::default();
    let u: Vec<f32> = (0..40).map(|i| if i == 0 { 0.0 } else { ((i * 7) % 5) as f32 - 2.0 }).collect();
    let (mut xs, mut vs) = (std::vec![0.0f64; 45], std::vec![0.0f64; 45]);
    for (t, &ut) in u.iter().enumerate() {
        let y = m.step(&mut s, &Kin::new(ut, 0.0, 0.0, 0.0));
        let t5 = t + 5;
        xs[t5] = f64::from(ut);
        let mut v = 0.0;
        for j in 0..3 {
            v += f64::from(b[j]) * xs[t5 - 1 - j];
        }
        for j in 0..5 {
            v -= f64::from(f[j]) * vs[t5 - 1 - j];
        }
        vs[t5] = v;
        assert!((f64::from(y) - v).abs() < 1e-5, "t={t}: {y} vs {v}");
    }
    // DC gain and steady start
    let m2 = m;
    let mut s = m2.initial_state(&Kin::new(2.0, 0.0, 0.0, 0.0));
    for _ in 0..10 {
        let y = m2.step(&mut s, &Kin::new(2.0, 0.0, 0.0, 0.0));
        let want = 2.0 * (0.55 / (1.0 + f.iter().map(|x| f64::from(*x)).sum::<f64>()));
        assert!((f64::from(y) - want).abs() < 1e-5, "{y} vs {want}");
    }
}

#[test]
fn nonlinearities_hand_computed() {
    let h = SigmoidNet { a: [2.0, -1.0], w: [1.5, 0.5], b: [0.1, -0.2], lin: 0.3, d: 0.05 };
    let u = 0.7f64;
    let sg = |s: f64| 1.0 / (1.0 + (-s).exp());
    let want = 0.3 * u + 0.05 + 2.0 * sg(1.5 * u + 0.1) - sg(0.5 * u - 0.2);
    assert!((f64::from(h.eval(u as f32)) - want).abs() < 1e-6);
    // x(t) = H(B) enters v one sample later (input delay 1), output W(v).
    let w = SigmoidNet { a: [1.0], w: [2.0], b: [0.0], lin: 0.0, d: 0.5 };
    let m = HammersteinWiener::<2, 1>::new(h, [1.0, 0.0, 0.0], [0.0; 5], w, -10.0, 10.0, 1e-3).unwrap();
    let mut s = State::default();
    let y0 = m.step(&mut s, &Kin::new(0.7, 0.0, 0.0, 0.0));
    assert!((f64::from(y0) - (0.5 + 0.5)).abs() < 1e-6, "v = 0 first: {y0}");
    let y1 = m.step(&mut s, &Kin::new(-3.0, 0.0, 0.0, 0.0));
    assert!((f64::from(y1) - (0.5 + sg(2.0 * want))).abs() < 1e-5);
}

#[test]
fn v_clamped_and_output_finite_on_huge_input() {
    let h = SigmoidNet { a: [1.0], w: [1.0], b: [0.0], lin: 1e6, d: 0.0 };
    let m = HammersteinWiener::<1, 1>::new(h, [1e6, 1e6, 1e6], [-0.5, 0.0, 0.0, 0.0, 0.0], identity(), -5.0, 7.0, 1e-3)
        .unwrap();
    let mut s = State::default();
    for u in [1e30f32, -1e30, 3.0e38, -3.0e38, 1.0] {
        let y = m.step(&mut s, &Kin::new(u, 0.0, 0.0, 0.0));
        assert!(y.is_finite() && (-5.0..=7.0).contains(&y));
        assert!(s.is_finite());
    }
}

#[test]
fn names_and_round_trip() {
    let names = Registered::PARAM_NAMES;
    assert_eq!(names[0], "h_a[14]");
    assert_eq!(names[7], "w_a[13]");
    // block lengths in the names add up to N_PARAMS
    let total: usize = names
        .iter()
        .map(|n| n.split_once('[').map_or(1, |(_, r)| r.trim_end_matches(']').parse::<usize>().unwrap()))
        .sum();
    assert_eq!(total, Registered::N_PARAMS);
    assert_eq!(Registered::N_PARAMS, 95);
    let mut p: Vec<f32> = (0..95).map(|i| ((i * 37 % 11) as f32 - 5.0) * 0.1).collect();
    // stable denominator and ordered v range
    let f0 = 3 * 14 + 2 + 3;
    p[f0..f0 + 5].copy_from_slice(&[0.1, -0.05, 0.02, 0.0, 0.01]);
    p[93] = -50.0;
    p[94] = 50.0;
    let m = Registered::from_params(&p, 1e-3).unwrap();
    let mut out = std::vec![0.0; 95];
    assert_eq!(m.write_params(&mut out), 95);
    assert_eq!(out, p);
    let mut bad = p.clone();
    bad[f0] = -2.5; // pole outside
    assert!(Registered::from_params(&bad, 1e-3).is_err());
    let mut bad = p.clone();
    bad[93] = 60.0;
    assert!(Registered::from_params(&bad, 1e-3).is_err());
    assert!(Registered::from_params(&p[..94], 1e-3).is_err());
}
