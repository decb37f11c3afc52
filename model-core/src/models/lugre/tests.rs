#![allow(clippy::unwrap_used, clippy::indexing_slicing)]
use super::*;
use std::vec::Vec;

/// Seed 000 Table 4 average.
fn avg(dt: f32) -> LuGre {
    LuGre::from_params(&SEED000_AVERAGE, dt).unwrap()
}

#[test]
fn equation_values_hand_computed() {
    let m = LuGre::new(2.0, 3.0, 0.5, 0.1, 4.0, 1.0, 1e-3).unwrap();
    // Small step up from z = 0.25: dz = α(1 − z)·ΔB = 2·0.75·1e-3.
    let mut s = State { z: 0.25, x_prev: 1.0 };
    let y = m.step(&mut s, &Kin::new(1.001, 2.0, 0.0, 0.0));
    let z = 0.25 + 2.0 * 0.75 * 1.0e-3;
    assert!((s.z - z).abs() < 2e-6, "{}", s.z);
    let zdot = 2.0 * (2.0 - 2.0 * z);
    let want = 3.0 / 2.0 * z + 0.1 * 2.0 + 4.0 * 1.001 + 0.5 / 2.0 * zdot + 1.0;
    assert!((y - want).abs() < 1e-4, "{y} vs {want}");
    // Exact over a long leg: z = s + (z0 − s)e^{−αL}.
    let mut s = State { z: 0.25, x_prev: 1.0 };
    m.step(&mut s, &Kin::new(0.3, -1.0, 0.0, 0.0));
    let want = -1.0 + (0.25f64 + 1.0) * (-2.0f64 * 0.7).exp();
    assert!((f64::from(s.z) - want).abs() < 1e-6);
}

fn rk4_vs_model(m: &LuGre, f: f64, dt: f64, periods: f64) -> f64 {
    let w = 2.0 * core::f64::consts::PI * f;
    let x = |t: f64| (1.5 + 1.5 * (w * t).sin(), 1.5 * w * (w * t).cos(), -1.5 * w * w * (w * t).sin());
    let a = f64::from(m.alpha);
    let zd = |z: f64, xd: f64| a * xd - a * xd.abs() * z;
    let steps = (periods / f / dt).round() as usize;
    let sub = 400;
    let h = dt / sub as f64;
    let (mut z, mut num, mut den) = (0.0f64, 0.0, 0.0);
    let first = x(0.0);
    let mut s = m.initial_state(&Kin::new(first.0 as f32, 0.0, 0.0, 0.0));
    for i in 0..steps {
        for j in 0..sub {
            let t = i as f64 * dt + j as f64 * h;
            let k1 = zd(z, x(t).1);
            let k2 = zd(z + 0.5 * h * k1, x(t + 0.5 * h).1);
            let k3 = zd(z + 0.5 * h * k2, x(t + 0.5 * h).1);
            let k4 = zd(z + h * k3, x(t + h).1);
            z += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        }
        let (xx, xd, xdd) = x((i + 1) as f64 * dt);
        let y = m.step(&mut s, &Kin::new(xx as f32, xd as f32, xdd as f32, 0.0));
        let yref = f64::from(m.beta) / a * z
            + f64::from(m.c) * xd
            + f64::from(m.k) * xx
            + f64::from(m.epsilon) / a * zd(z, xd)
            + f64::from(m.t0);
        num += (yref - f64::from(y)).powi(2);
        den += yref * yref;
    }
    (num / den).sqrt()
}

#[test]
fn exact_update_matches_rk4() {
    for dt in [1.0 / 500.0, 1.0 / 3000.0] {
        for f in [1.0, 5.0, 9.0] {
            let e = rk4_vs_model(&avg(dt as f32), f, dt, 3.0);
            assert!(e < 5e-5, "f={f} dt={dt}: {e}");
            // A stiffer α (ten times Table 4) is still exact at one step per sample.
            let stiff = LuGre::new(43.0, 5.771, 0.3, -0.151, 4.297, 5.225, dt as f32).unwrap();
            let e = rk4_vs_model(&stiff, f, dt, 3.0);
            assert!(e < 5e-5, "stiff f={f} dt={dt}: {e}");
        }
    }
}

#[test]
fn z_bounded_and_saturates() {
    let m = avg(1e-3);
    let mut s = State::default();
    for i in 0..5000 {
        m.step(&mut s, &Kin::new(i as f32 * 0.01, 10.0, 0.0, 0.0));
        assert!(s.z.abs() <= 1.0);
    }
    assert!((s.z - 1.0).abs() < 1e-6);
    // z follows sgn(Ḃ): the (B, z) loop is clockwise (∮ z dB > 0, dissipative), so its
    // shoelace sum is negative.
    let n = 600;
    let mut s = State::default();
    let mut pts = Vec::new();
    for i in 0..(3 * n) {
        let b = (2.0 * core::f32::consts::PI * i as f32 / n as f32).sin();
        m.step(&mut s, &Kin::new(b, 0.0, 0.0, 0.0));
        if i >= 2 * n {
            pts.push((f64::from(b), f64::from(s.z)));
        }
    }
    let mut area = 0.0;
    for i in 0..n {
        let (p, q) = (pts[i], pts[(i + 1) % n]);
        area += p.0 * q.1 - q.0 * p.1;
    }
    assert!(area < -0.2, "{area}");
}

#[test]
fn rejects_invalid() {
    assert!(LuGre::new(0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1e-3).is_err());
    assert!(LuGre::new(-1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1e-3).is_err());
    assert!(LuGre::new(1e-30, 1e10, 0.0, 0.0, 0.0, 0.0, 1e-3).is_err());
    assert!(LuGre::new(1.0, f32::INFINITY, 0.0, 0.0, 0.0, 0.0, 1e-3).is_err());
    assert!(LuGre::from_params(&[1.0; 5], 1e-3).is_err());
    let p = [4.312, 5.771, 0.003, -0.151, 4.297, 5.225];
    let mut out = [0.0; 6];
    assert_eq!(LuGre::from_params(&p, 1e-3).unwrap().write_params(&mut out), 6);
    assert_eq!(out, p);
}
