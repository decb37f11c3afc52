#![allow(clippy::unwrap_used, clippy::indexing_slicing)]
use super::*;
use std::vec::Vec;

const DT: f32 = 1.0 / 500.0;

fn bw(beta: f32, gamma: f32, delta: f32, n: f32) -> BoucWen {
    BoucWen::new(1.0, beta, gamma, delta, n, 0.0, 0.0, 0.0, DT).unwrap()
}

/// f64 RHS of eq. 2 written directly.
fn zdot(m: &BoucWen, z: f64, xd: f64) -> f64 {
    let (b, g, d, n) = (f64::from(m.beta), f64::from(m.gamma), f64::from(m.delta), f64::from(m.n));
    d * xd - b * xd * z.abs().powf(n) - g * xd.abs() * z * z.abs().powf(n - 1.0)
}

/// Fine RK4 in f64 of ż along x(t); returns z at each sample.
fn rk4_path(m: &BoucWen, x: &dyn Fn(f64) -> (f64, f64), dt: f64, steps: usize, sub: usize) -> Vec<f64> {
    let mut z = 0.0f64;
    let mut out = Vec::with_capacity(steps);
    let h = dt / sub as f64;
    for i in 0..steps {
        for j in 0..sub {
            let t = i as f64 * dt + j as f64 * h;
            let k1 = zdot(m, z, x(t).1);
            let k2 = zdot(m, z + 0.5 * h * k1, x(t + 0.5 * h).1);
            let k3 = zdot(m, z + 0.5 * h * k2, x(t + 0.5 * h).1);
            let k4 = zdot(m, z + h * k3, x(t + h).1);
            z += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        }
        out.push(z);
    }
    out
}

/// Step the f32 model once per sample with the analytic rate; z after each step
/// (the first step leaves z at 0 and corresponds to t = 0).
fn model_path(m: &BoucWen, x: &dyn Fn(f64) -> (f64, f64, f64), dt: f64, steps: usize) -> Vec<f64> {
    let first = x(0.0);
    let k0 = Kin::new(first.0 as f32, first.1 as f32, first.2 as f32, 0.0);
    let mut s = m.initial_state(&k0);
    let mut out = Vec::with_capacity(steps);
    for i in 1..=steps {
        let (xx, xd, xdd) = x(i as f64 * dt);
        m.step(&mut s, &Kin::new(xx as f32, xd as f32, xdd as f32, 0.0));
        out.push(f64::from(s.z));
    }
    out
}

fn rel_rms(a: &[f64], b: &[f64]) -> f64 {
    let num: f64 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum();
    let den: f64 = a.iter().map(|x| x * x).sum();
    (num / den).sqrt()
}

fn sine(amp: f64, off: f64, f: f64) -> impl Fn(f64) -> (f64, f64, f64) {
    let w = 2.0 * core::f64::consts::PI * f;
    move |t| (off + amp * (w * t).sin(), amp * w * (w * t).cos(), -amp * w * w * (w * t).sin())
}

/// Compare exact/SDIRK core against fine RK4 over `periods` periods of a sine.
fn err_vs_rk4(m: &BoucWen, amp: f64, off: f64, f: f64, dt: f64, periods: f64) -> f64 {
    let x = sine(amp, off, f);
    let steps = (periods / f / dt).round() as usize;
    let refz = rk4_path(m, &|t| (x(t).0, x(t).1), dt, steps, 400);
    let got = model_path(m, &x, dt, steps);
    let e = rel_rms(&refz, &got);
    std::eprintln!("err n={} f={f} dt={dt}: {e:.3e}", m.n);
    e
}

#[test]
fn equation_value_hand_computed() {
    // One tiny step from z = 0.5: dz ≈ ż·Δt with ż from eq. 2 by hand.
    let m = BoucWen::new(2.0, 0.3, 0.7, 1.5, 1.0, 0.1, 4.0, 0.25, DT).unwrap();
    let mut s = State { z: 0.5, x_prev: 1.0 };
    let dx = 1.0e-3f32;
    let y = m.step(&mut s, &Kin::new(1.0 + dx, 2.0, 0.0, 0.0));
    // ẋ > 0, z > 0: dz/dx = δ − (β+γ)·z = 1.5 − 1.0·0.5 = 1.0
    assert!((s.z - (0.5 + 1.0e-3)).abs() < 2e-6, "{}", s.z);
    // T = c·ẋ + k·(x − x0) + α·z
    let want = 0.1 * 2.0 + 4.0 * (1.001 - 0.25) + 2.0 * s.z;
    assert!((y - want).abs() < 1e-5);
    // ẋ < 0, z > 0: dz/dx = δ − (β − γ)·z = 1.5 + 0.4·z
    let mut s = State { z: 0.5, x_prev: 1.0 };
    m.step(&mut s, &Kin::new(1.0 - dx, -2.0, 0.0, 0.0));
    assert!((s.z - (0.5 - 1.7e-3)).abs() < 2e-6, "{}", s.z);
}

#[test]
fn saturates_at_bound() {
    // Long monotone travel ends at the equilibrium sgn(δ)·z*.
    for (b, g, d, n) in [
        (0.5, 0.5, 2.0, 1.0),
        (0.2, 0.9, 3.0, 2.0),
        (0.3, 0.6, 1.0, 3.5),
        (0.4, 1.0, -1.5, 1.0),
        (-0.5, 1.0, -2.0, 2.0),
    ] {
        let m = bw(b, g, d, n);
        let zs = (f64::from(d).abs() / (f64::from(g) + f64::from(d).signum() * f64::from(b))).powf(1.0 / f64::from(n));
        assert!((f64::from(m.z_bound()) - zs).abs() < 1e-5 * zs);
        let mut s = State::default();
        for i in 1..=2000 {
            m.step(&mut s, &Kin::new(i as f32 * 0.01, 5.0, 0.0, 0.0));
        }
        let want = f64::from(d).signum() * zs;
        assert!((f64::from(s.z) - want).abs() < 1e-4 * zs, "n={n} z={} want {want}", s.z);
    }
}

#[test]
fn exact_n1_matches_rk4() {
    // seed 000 Table 3 average read in Wen's naming (bounded), and the 7 Hz set as printed.
    let sets = [
        BoucWen::new_wen_naming(2.162, -1.486, 1.0, 0.400, 1.0, -0.077, 5.861, 0.0, DT).unwrap(),
        BoucWen::new(0.641, 1.0, 0.847, 0.488, 1.0, -0.047, 5.294, 0.0, DT).unwrap(),
        bw(-0.3, 0.8, 2.5, 1.0),
    ];
    for m in &sets {
        for f in [1.0, 5.0, 9.0] {
            let e = err_vs_rk4(m, 1.5, 1.5, f, f64::from(DT), 3.0);
            assert!(e < 1e-4, "n=1 f={f}: {e}");
        }
    }
}

#[test]
fn exact_n2_matches_rk4() {
    // Seed 003 damper set (x in mm), Wen's naming: A = 30.852, β = 0.081, γ = 1.507.
    let m = BoucWen::new_wen_naming(173.27, 30.852, 0.081, 1.507, 2.0, 8.907, 1.984, -20.161, DT).unwrap();
    let others = [bw(0.6, 0.3, 2.0, 2.0), bw(-0.5, 1.0, -2.0, 2.0), bw(0.3, 0.8, -1.0, 2.0)];
    for f in [1.0, 5.0, 9.0] {
        let e = err_vs_rk4(&m, 4.0, 0.0, f, f64::from(DT), 3.0);
        assert!(e < 1e-4, "seed003 f={f}: {e}");
    }
    for m in &others {
        for f in [1.0, 9.0] {
            let e = err_vs_rk4(m, 1.5, 0.3, f, f64::from(DT), 3.0);
            assert!(e < 1e-4, "n=2 {m:?} f={f}: {e}");
        }
    }
}

#[test]
fn general_n_sdirk_accuracy() {
    for n in [1.5f32, 3.0] {
        let m = bw(0.5, 0.5, 2.0, n);
        for f in [1.0, 9.0] {
            let e = err_vs_rk4(&m, 1.5, 0.0, f, f64::from(DT), 3.0);
            assert!(e < 2e-3, "n={n} f={f}: {e}");
        }
    }
}

#[test]
fn general_path_agrees_with_exact_for_n2() {
    // Force the SDIRK path on n = 2 and compare with the exact Riccati update.
    let mut g = bw(0.6, 0.3, 2.0, 2.0);
    let exact = g;
    g.exp = Exponent::General;
    let x = sine(1.5, 0.0, 5.0);
    let a = model_path(&exact, &x, 1.0 / 3000.0, 1800);
    let b = model_path(&g, &x, 1.0 / 3000.0, 1800);
    assert!(rel_rms(&a, &b) < 1e-3, "{}", rel_rms(&a, &b));
}

#[test]
fn zero_crossing_split_is_exact() {
    // One big step from z = −z* upward: compare with many tiny steps.
    let m = bw(0.2, 0.8, 2.0, 1.0);
    let zs = m.z_bound();
    let mut big = State { z: -zs, x_prev: 0.0 };
    m.step(&mut big, &Kin::new(1.3, 1.0, 0.0, 0.0));
    let mut fine = State { z: -zs, x_prev: 0.0 };
    for i in 1..=100_000 {
        m.step(&mut fine, &Kin::new(1.3 * i as f32 / 100_000.0, 1.0, 0.0, 0.0));
    }
    assert!((big.z - fine.z).abs() < 1e-4, "{} vs {}", big.z, fine.z);
}

#[test]
fn reversal_split_uses_turning_point() {
    // x goes 0 → 1 → 0.9 within one step; with the turning point the result equals
    // two explicit steps through x = 1.
    let m = bw(0.5, 0.5, 2.0, 1.0);
    let mut two = State { z: 0.0, x_prev: 0.0 };
    m.step(&mut two, &Kin::new(1.0, 0.0, 0.0, 0.0));
    m.step(&mut two, &Kin::new(0.9, 0.0, 0.0, 0.0));
    // Quadratic ending at 0.9 with extremum 1.0 at τ = 0.5·dt before the sample.
    let tau = 0.5 * DT;
    let ddx = -2.0 * 0.1 / (tau * tau);
    let dx = ddx * tau;
    let mut one = State { z: 0.0, x_prev: 0.0 };
    m.step(&mut one, &Kin::new(0.9, dx, ddx, 0.0));
    assert!((one.z - two.z).abs() < 1e-4, "{} vs {}", one.z, two.z);
}

/// Loop of the hysteretic part z(x) over one period after transients.
fn z_loop(m: &BoucWen, amp: f32) -> (f64, f64, f64) {
    let n = 400;
    let mut s = State::default();
    let w = 2.0 * core::f32::consts::PI / n as f32;
    let (mut pts, mut slope0) = (Vec::new(), 0.0f64);
    for i in 0..(4 * n) {
        let x = amp * (w * i as f32).sin();
        m.step(&mut s, &Kin::new(x, 0.0, 0.0, 0.0));
        if i >= 3 * n {
            pts.push((f64::from(x), f64::from(s.z)));
        }
    }
    // shoelace area, height (max z), slope at z ≈ 0 while loading
    let mut area = 0.0;
    for i in 0..pts.len() {
        let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
        area += a.0 * b.1 - b.0 * a.1;
    }
    let hmax = pts.iter().map(|p| p.1).fold(f64::MIN, f64::max);
    for i in 1..pts.len() {
        let (a, b) = (pts[i - 1], pts[i]);
        if b.0 > a.0 && a.1 <= 0.0 && b.1 > 0.0 {
            slope0 = (b.1 - a.1) / (b.0 - a.0);
        }
    }
    (0.5 * area.abs(), hmax, slope0)
}

#[test]
fn seed003_influence_of_a() {
    // Seed 003 Fig. 7 (β = 0.5, γ = −0.4 in its naming, n = 1): a larger A gives a
    // larger loop and a steeper slope at z = 0 (which equals A, Table 4).
    let mut prev = (0.0, 0.0, 0.0);
    for a in [0.5f32, 1.0, 2.0, 4.0] {
        let m = BoucWen::new_wen_naming(1.0, a, 0.5, -0.4, 1.0, 0.0, 0.0, 0.0, DT).unwrap();
        let l = z_loop(&m, 2.0);
        assert!(l.0 > prev.0 && l.1 > prev.1 && l.2 > prev.2, "A={a}: {l:?} after {prev:?}");
        assert!((l.2 - f64::from(a)).abs() < 0.05 * f64::from(a), "slope at z=0 {} vs A {a}", l.2);
        prev = l;
    }
}

#[test]
fn seed003_table4_slopes() {
    // Table 4 (Wen's naming): dz/dx = A − (γ + β·sgn(ẋ z))|z|ⁿ.
    let (a, bw_, gw, n) = (1.0f32, 0.5f32, 0.2f32, 2.0f32);
    let m = BoucWen::new_wen_naming(1.0, a, bw_, gw, n, 0.0, 0.0, 0.0, DT).unwrap();
    let h = 1e-4f32;
    for (z, dir) in [(0.6f32, 1.0f32), (0.6, -1.0), (-0.6, 1.0), (-0.6, -1.0)] {
        let mut s = State { z, x_prev: 0.0 };
        m.step(&mut s, &Kin::new(dir * h, 0.0, 0.0, 0.0));
        let slope = (s.z - z) / (dir * h);
        let want = a - (gw + bw_ * (dir * z).signum()) * z.abs().powf(n);
        assert!((slope - want).abs() < 2e-2, "z={z} dir={dir}: {slope} vs {want}");
    }
}

#[test]
fn seed003_influence_of_n_and_beta_gamma() {
    // Larger n: sharper transition → the loop approaches the elasto-plastic
    // rectangle, so its area grows with n (seed 003 Fig. 8), saturating beyond n ≈ 2.
    let mut prev = 0.0;
    let mut areas = Vec::new();
    for n in [1.0f32, 1.5, 2.0, 3.0, 5.0] {
        let m = BoucWen::new_wen_naming(1.0, 1.0, 0.5, 0.5, n, 0.0, 0.0, 0.0, DT).unwrap();
        let l = z_loop(&m, 3.0);
        assert!(l.0 > prev, "n={n}: area {} after {prev}", l.0);
        prev = l.0;
        areas.push(l.0);
    }
    assert!(areas[1] - areas[0] > areas[4] - areas[3], "n effect should fade beyond 2: {areas:?}");
    // Seed 003 Fig. 12: β + γ constant (0.8/0.2 vs 0.5/0.5) → nearly the same loop.
    let a = z_loop(&BoucWen::new_wen_naming(1.0, 1.0, 0.8, 0.2, 1.0, 0.0, 0.0, 0.0, DT).unwrap(), 2.0);
    let b = z_loop(&BoucWen::new_wen_naming(1.0, 1.0, 0.5, 0.5, 1.0, 0.0, 0.0, 0.0, DT).unwrap(), 2.0);
    assert!((a.1 - b.1).abs() < 0.05 * b.1, "heights {} {}", a.1, b.1);
    // Seed 003 Fig. 10: increasing γ (Wen's, on ẋ|z|ⁿ) flattens the loop: lower height.
    let mut prev_h = f64::MAX;
    for gw in [-0.3f32, 0.0, 0.3, 0.9] {
        let l = z_loop(&BoucWen::new_wen_naming(1.0, 1.0, 0.5, gw, 1.0, 0.0, 0.0, 0.0, DT).unwrap(), 2.0);
        assert!(l.1 < prev_h, "γ={gw}: height {} after {prev_h}", l.1);
        prev_h = l.1;
    }
    // Seed 003 Table 5 / Fig. 9: β (Wen's) controls the stiffness change at reversal:
    // β = 0 → same |slope| on loading and unloading at given |z|; β > 0 softening
    // (unloading steeper than loading, since dz/dx = A − (γ ± β)|z|ⁿ).
    let m = BoucWen::new_wen_naming(1.0, 1.0, 0.6, 0.2, 1.0, 0.0, 0.0, 0.0, DT).unwrap();
    let h = 1e-4f32;
    let mut up = State { z: 0.5, x_prev: 0.0 };
    m.step(&mut up, &Kin::new(h, 0.0, 0.0, 0.0));
    let mut dn = State { z: 0.5, x_prev: 0.0 };
    m.step(&mut dn, &Kin::new(-h, 0.0, 0.0, 0.0));
    assert!((0.5 - dn.z) > (up.z - 0.5), "unloading slope must exceed loading slope");
}

#[test]
fn rejects_invalid() {
    assert!(BoucWen::new(1.0, 1.0, -0.1, 1.0, 1.0, 0.0, 0.0, 0.0, DT).is_err()); // γ < 0
    assert!(BoucWen::new(1.0, -1.0, 0.5, 1.0, 1.0, 0.0, 0.0, 0.0, DT).is_err()); // γ+β ≤ 0
    assert!(BoucWen::new(1.0, 1.0, 0.4, -1.486, 1.0, 0.0, 0.0, 0.0, DT).is_err()); // Table 3 as printed
    assert!(BoucWen::new(1.0, 0.4, 1.0, -1.486, 1.0, 0.0, 0.0, 0.0, DT).is_ok()); // swapped
    assert!(BoucWen::new(1.0, 1.0, 1.0, 1.0, 0.5, 0.0, 0.0, 0.0, DT).is_err()); // n < 1
    assert!(BoucWen::new(1.0, 1.0, 1.0, 1.0, 11.0, 0.0, 0.0, 0.0, DT).is_err()); // n > 10
    assert!(BoucWen::new(f32::NAN, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, DT).is_err());
    assert!(BoucWen::new(1.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0).is_err());
    assert!(BoucWen::new(1.0, 1.0e-12, 0.0, 1.0e6, 1.0, 0.0, 0.0, 0.0, DT).is_err()); // z* huge
    assert!(BoucWen::from_params(&[1.0; 7], DT).is_err());
}

#[test]
fn round_trip() {
    // δ < 0 needs γ − β > 0.
    let p = [2.0, 0.2, 0.7, -1.5, 1.7, 0.1, 4.0, 0.25];
    let m = BoucWen::from_params(&p, DT).unwrap();
    let mut out = [0.0; 8];
    assert_eq!(m.write_params(&mut out), 8);
    assert_eq!(out, p);
}
