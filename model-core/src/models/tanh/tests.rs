#![allow(clippy::unwrap_used, clippy::indexing_slicing)]
use super::*;
use std::vec::Vec;

#[test]
fn matches_eq11_12() {
    // Seed 000 Table 5 average.
    let m = Tanh::from_params(&SEED000_AVERAGE, 2e-3).unwrap();
    for (b, bd) in [(1.5f64, 2.0f64), (-0.7, -3.0), (0.0, 1.0), (2.9, -0.2)] {
        let y = m.step(&mut (), &Kin::new(b as f32, bd as f32, 0.0, 0.0));
        let z = (1.969 * bd + 1.603 * b.signum() * if b == 0.0 { 0.0 } else { 1.0 }).tanh();
        let want = -0.120 * bd + 4.790 * b + 0.495 * z + 0.587;
        assert!((f64::from(y) - want).abs() < 1e-5, "{y} vs {want}");
    }
}

/// Seed 000 Fig. 4: γ sets the width of the loop and α its height. The sign(B) term
/// separates the branches in the torque–rate plane (Kwok's force–velocity loop), whose
/// area is `α·∫[tanh(βu + γ) − tanh(βu − γ)]du`, increasing in γ and α.
#[test]
fn loop_width_and_height() {
    let area_height = |alpha: f32, gamma: f32| {
        let m = Tanh::new(alpha, 1.0, gamma, 0.0, 0.0, 0.0, 1e-3).unwrap();
        let n = 1000;
        let w = 2.0 * core::f32::consts::PI;
        let pts: Vec<(f64, f64)> = (0..n)
            .map(|i| {
                let t = (i as f32 + 0.5) / n as f32;
                let (b, bd) = ((w * t).sin(), (w * t).cos());
                (f64::from(bd), f64::from(m.step(&mut (), &Kin::new(b, bd, 0.0, 0.0))))
            })
            .collect();
        let mut a = 0.0;
        for i in 0..n {
            let (p, q) = (pts[i], pts[(i + 1) % n]);
            a += p.0 * q.1 - q.0 * p.1;
        }
        let hi = pts.iter().map(|p| p.1).fold(f64::MIN, f64::max);
        (0.5 * a.abs(), hi)
    };
    let mut prev = 0.0;
    for g in [0.1f32, 0.3, 0.6, 1.0, 2.0] {
        let (a, _) = area_height(1.0, g);
        assert!(a > prev, "γ widens: {a} after {prev}");
        // closed form α∫_{-1}^{1}[tanh(u+γ) − tanh(u−γ)]du = α[ln cosh(u+γ) − ln cosh(u−γ)]
        let gg = f64::from(g);
        let want = 2.0 * ((1.0 + gg).cosh().ln() - (1.0 - gg).cosh().ln());
        assert!((a - want).abs() < 1e-2 * want, "{a} vs {want}");
        prev = a;
    }
    let (a2, h2) = area_height(1.0, 1.0);
    let (a3, h3) = area_height(2.0, 1.0);
    assert!(a3 > a2 && h3 > h2, "α scales the height: {a2} {a3} {h2} {h3}");
}

#[test]
fn rejects_non_finite() {
    assert!(Tanh::new(f32::NAN, 0.0, 0.0, 0.0, 0.0, 0.0, 1e-3).is_err());
    assert!(Tanh::from_params(&[0.0; 5], 1e-3).is_err());
    let p = [0.495, 1.969, 1.603, -0.120, 4.790, 0.587];
    let mut out = [0.0; 6];
    Tanh::from_params(&p, 1e-3).unwrap().write_params(&mut out);
    assert_eq!(out, p);
}
