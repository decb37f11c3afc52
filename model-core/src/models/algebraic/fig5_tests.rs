#![allow(clippy::unwrap_used, clippy::indexing_slicing)]
use super::*;
use std::vec::Vec;

/// One period (after a period of transient) of the T–B loop under the seed 000 Fig. 5
/// input, B = sin(2π·1 Hz·t) (−1 to 1), sampled at `n` points per period with the
/// analytic rate. Returns (shoelace area, peak-to-peak torque).
fn loop_of(c: f32, alpha: f32) -> (f64, f64) {
    let n = 2000;
    let m = Algebraic::new(1.0, c, alpha, 0.0, 1.0 / n as f32).unwrap();
    let w = 2.0 * core::f64::consts::PI;
    let pts: Vec<(f64, f64)> = (0..2 * n)
        .map(|i| {
            let t = i as f64 / n as f64;
            let (b, bd) = ((w * t).sin(), w * (w * t).cos());
            (b, f64::from(m.step(&mut (), &Kin::new(b as f32, bd as f32, 0.0, 0.0))))
        })
        .skip(n)
        .collect();
    let mut s = 0.0;
    for i in 0..n {
        let (p, q) = (pts[i], pts[(i + 1) % n]);
        s += p.0 * q.1 - q.0 * p.1;
    }
    let hi = pts.iter().map(|p| p.1).fold(f64::MIN, f64::max);
    let lo = pts.iter().map(|p| p.1).fold(f64::MAX, f64::min);
    (0.5 * s.abs(), hi - lo)
}

#[test]
fn fig5_loop_area_grows_with_c() {
    // ∮T dB = c·∮Ḃ dB = c·∫Ḃ²dt = c·2π² for a unit 1 Hz sine: linear in c.
    let mut prev = 0.0;
    for c in [0.01f32, 0.05, 0.1, 0.2, 0.4] {
        let (a, _) = loop_of(c, 0.5);
        let want = f64::from(c) * 2.0 * core::f64::consts::PI.powi(2);
        assert!((a - want).abs() < 1e-3 * want + 1e-6, "c={c}: {a} vs {want}");
        assert!(a > prev);
        prev = a;
    }
}

#[test]
fn fig5_loop_size_grows_with_alpha() {
    // α|B|B³ is a single-valued function of B: it bends the loop but adds no enclosed
    // area (the shoelace area stays c·2π²); what grows with α is the loop's extent in T
    // (the "size" of the curves in Fig. 5a).
    let (a0, h0) = loop_of(0.1, 0.0);
    let mut prev_h = h0;
    for alpha in [0.5f32, 1.0, 2.0, 4.0] {
        let (a, h) = loop_of(0.1, alpha);
        assert!((a - a0).abs() < 1e-3 * a0, "area must not depend on α: {a} vs {a0}");
        assert!(h > prev_h, "α={alpha}: extent {h} after {prev_h}");
        prev_h = h;
    }
}
