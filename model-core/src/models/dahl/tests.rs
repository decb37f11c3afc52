#![allow(clippy::unwrap_used, clippy::indexing_slicing)]
use super::*;

/// Eq. 8 and eq. 10 by hand at a state with z ≠ 0 and u ≠ 0.
#[test]
fn force_matches_eq8() {
    let m = Dahl::new(DYKE_PLAUSIBLE, 1e-3).unwrap();
    let k = Kin::new(0.4, -3.0, 0.0, 1.5);
    let (c0, fd) = (20.0 + 3.0 * 1.2, 85.0 + 400.0 * 1.2);
    let want = 5.0 * 0.4 + c0 * -3.0 + fd * 0.25 - 71.5;
    assert!((m.force(0.25, 1.2, &k) - want).abs() < 1e-3);
    let mut v = [0.0; 8];
    assert_eq!(m.write_params(&mut v), 8);
    assert_eq!(Dahl::from_params(&v, 1e-3).unwrap(), m);
    assert!(Dahl::from_params(&v[..7], 1e-3).is_err());
    assert!(Dahl::new(Params { sigma: 0.0, ..DYKE_PLAUSIBLE }, 1e-3).is_err());
    assert!(Dahl::new(Params { fdu: -1.0, ..DYKE_PLAUSIBLE }, 1e-3).is_err());
    assert!(Dahl::new(Params { k0: f32::INFINITY, ..DYKE_PLAUSIBLE }, 1e-3).is_err());
}

/// f64 RK4 of eq. 9 and eq. 11 with 200 sub-steps per sample against the one-step update,
/// on a sine with reversals between samples and a swinging command, at 500 Hz.
#[test]
fn one_step_matches_fine_rk4() {
    let p = DYKE_PLAUSIBLE;
    let fs = 500.0f64;
    let dt = 1.0 / fs;
    let w = 2.0 * core::f64::consts::PI * 7.0;
    let wv = 2.0 * core::f64::consts::PI * 1.1;
    let inp = |t: f64| (0.8 * (w * t).sin(), 0.8 * w * (w * t).cos(), 1.2 - 1.2 * (wv * t).cos());
    let sigma = f64::from(p.sigma);
    let eta = f64::from(p.eta);
    let f = |s: [f64; 2], t: f64| {
        let (_, xd, v) = inp(t);
        let sg = if xd > 0.0 {
            1.0
        } else if xd < 0.0 {
            -1.0
        } else {
            0.0
        };
        [sigma * xd * (1.0 - s[0] * sg), -eta * (s[1] - v.max(0.0))]
    };
    let m = Dahl::new(p, dt as f32).unwrap();
    let mut ms = State::default();
    let (x0, _, v0) = inp(0.0);
    let _ = x0;
    let mut s = [0.0, v0];
    let (mut num, mut den, mut mean, mut refs, mut outs) = (0.0, 0.0, 0.0, vec![], vec![]);
    let sub = 200;
    let h = dt / sub as f64;
    for i in 0..1000 {
        let t = i as f64 * dt;
        if i > 0 {
            for j in 0..sub {
                let tt = t - dt + j as f64 * h;
                let add = |s: [f64; 2], k: [f64; 2], c: f64| [s[0] + c * k[0], s[1] + c * k[1]];
                let k1 = f(s, tt);
                let k2 = f(add(s, k1, h / 2.0), tt + h / 2.0);
                let k3 = f(add(s, k2, h / 2.0), tt + h / 2.0);
                let k4 = f(add(s, k3, h), tt + h);
                for q in 0..2 {
                    s[q] += h / 6.0 * (k1[q] + 2.0 * k2[q] + 2.0 * k3[q] + k4[q]);
                }
            }
        }
        let (x, xd, v) = inp(t);
        let (c0, fd) = (f64::from(p.c0s) + f64::from(p.c0d) * s[1], f64::from(p.fds) + f64::from(p.fdu) * s[1]);
        let fref = f64::from(p.k0) * x + c0 * xd + fd * s[0] - f64::from(p.f0);
        let out = m.step(&mut ms, &Kin::new(x as f32, xd as f32, 0.0, v as f32));
        assert!(ms.z.abs() <= 1.0);
        refs.push(fref);
        outs.push(f64::from(out));
    }
    for r in &refs {
        mean += r / refs.len() as f64;
    }
    for (o, r) in outs.iter().zip(&refs) {
        num += (o - r) * (o - r);
        den += (r - mean) * (r - mean);
    }
    let e = (num / den).sqrt();
    println!("dahl 7 Hz at 500 Hz, swinging command: R-RMSE {:.4} %", 100.0 * e);
    assert!(e < 1e-4, "{e}");
}

/// Exact Dahl update along a monotone increment: dz/dx = σ(1 − z·sgn Δx).
#[test]
fn z_update_is_exact_and_bounded() {
    let m = Dahl::new(DYKE_PLAUSIBLE, 1e-3).unwrap();
    let want = 1.0 - (1.0 - 0.2f64) * (-15.0f64 * 0.05).exp();
    assert!((f64::from(m.advance_z(0.2, 0.05)) - want).abs() < 1e-6);
    let want = -1.0 + (1.0 + 0.2f64) * (-15.0f64 * 0.05).exp();
    assert!((f64::from(m.advance_z(0.2, -0.05)) - want).abs() < 1e-6);
    assert_eq!(m.advance_z(0.3, 0.0), 0.3);
    assert!((m.advance_z(0.3, 1e30) - 1.0).abs() < 1e-6);
    assert!((m.advance_z(0.3, -1e30) + 1.0).abs() < 1e-6);
}
