#![allow(clippy::unwrap_used, clippy::indexing_slicing)]
use super::*;

fn kin(x: f32) -> Kin {
    Kin::new(x, 0.0, 0.0, 0.0)
}

#[allow(clippy::too_many_arguments)]
fn abw(
    d: f32,
    a: f32,
    beta: f32,
    gamma: f32,
    n: f32,
    z0: f32,
    delta: f32,
    p: f32,
    q: f32,
    v: Asymmetry,
    dt: f32,
) -> BoucWenAsym {
    BoucWenAsym::new(0.5, 1.0, d, a, beta, gamma, n, z0, delta, p, q, v, dt).unwrap()
}

/// Seed 004 Table A17 (ABW₁, eq. 30), signs as printed.
pub(crate) const A17: [f32; 12] = SEED004_A17;
/// Seed 004 Table A18 (ABW₂, eq. 31), signs as printed.
pub(crate) const A18: [f32; 12] = SEED004_A18;

/// Monotone loading from z = 0 for n = 1: `z(x) = z̄·(1 − e^{−c₁x/D})` (eq. 26
/// integrated by hand), whatever the step size.
#[test]
fn n1_loading_is_exact() {
    let (d, a, b, g) = (2.0f32, 1.5f32, 0.7f32, 0.3f32);
    let m = abw(d, a, b, g, 1.0, 0.0, 0.0, 0.0, 0.0, Asymmetry::Linear, 1e-3);
    let mut s = m.initial_state(&kin(0.0));
    m.step(&mut s, &kin(0.0));
    for (i, x) in [0.05f32, 0.3, 0.31, 1.0, 2.5].iter().enumerate() {
        let y = m.step(&mut s, &kin(*x));
        let zbar = f64::from(a / (b + g));
        let want_z = zbar * (1.0 - (-(f64::from(b + g)) * f64::from(*x) / f64::from(d)).exp());
        assert!((f64::from(s.z) - want_z).abs() < 2e-6, "step {i}: z {} vs {want_z}", s.z);
        let want_y = 0.5 * f64::from(*x) + 0.5 * f64::from(d) * want_z;
        assert!((f64::from(y) - want_y).abs() < 1e-5);
    }
}

/// n = 2, monotone loading from 0: `z = z̄·tanh(√(A(β+γ))·x/D)`.
#[test]
fn n2_loading_is_exact() {
    let (d, a, b, g) = (1.5f32, 2.0f32, 1.0f32, 3.0f32);
    let m = abw(d, a, b, g, 2.0, 0.0, 0.0, 0.0, 0.0, Asymmetry::Linear, 1e-3);
    let mut s = m.initial_state(&kin(0.0));
    m.step(&mut s, &kin(0.0));
    for x in [0.1f32, 0.15, 0.6, 2.0] {
        m.step(&mut s, &kin(x));
        let (a, c) = (f64::from(a), f64::from(b + g));
        let want = (a / c).sqrt() * ((a * c).sqrt() * f64::from(x) / f64::from(d)).tanh();
        assert!((f64::from(s.z) - want).abs() < 2e-6, "x={x}: {} vs {want}", s.z);
    }
}

/// Independent f64 reference: eq. 28 with RK4, `sub` substeps per sample, on the
/// analytic input `x(t)`, `ẋ(t)`.
fn rk4_reference(pr: &[f32; 12], x: &dyn Fn(f64) -> (f64, f64), fs: f64, samples: usize, sub: usize) -> Vec<f64> {
    let p: Vec<f64> = pr.iter().map(|v| f64::from(*v)).collect();
    let (alpha, kappa, d, a, beta, gamma, n, z0, delta, pp, q) =
        (p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], p[9], p[10]);
    let variant = pr[11];
    let rhs = |z: f64, t: f64| {
        let (xv, xd) = x(t);
        let sg = if xd > 0.0 {
            1.0
        } else if xd < 0.0 {
            -1.0
        } else {
            0.0
        };
        let psi = if variant == 1.0 {
            delta * xv * sg
        } else {
            delta * (1.0 + sg) * (1.0 / (1.0 + (-pp * (xv - q)).exp()) - 0.5)
        };
        (a * xd - beta * xd.abs() * z.abs().powf(n - 1.0) * z - gamma * xd * z.abs().powf(n) + psi) / d
    };
    let h = 1.0 / (fs * sub as f64);
    let mut z = z0;
    let mut out = Vec::with_capacity(samples);
    for k in 0..samples {
        let t0 = k as f64 / fs;
        out.push(alpha * kappa * x(t0).0 + (1.0 - alpha) * d * kappa * z);
        for j in 0..sub {
            let t = t0 + j as f64 * h;
            let k1 = rhs(z, t);
            let k2 = rhs(z + 0.5 * h * k1, t + 0.5 * h);
            let k3 = rhs(z + 0.5 * h * k2, t + 0.5 * h);
            let k4 = rhs(z + h * k3, t + h);
            z += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        }
    }
    out
}

/// R-RMSE (seed 000 eq. 20) of the f32 model stepped once per sample.
fn r_rmse(pr: &[f32; 12], x: &dyn Fn(f64) -> (f64, f64), fs: f64, samples: usize) -> f64 {
    let reference = rk4_reference(pr, x, fs, samples, 200);
    let m = BoucWenAsym::from_params(pr, (1.0 / fs) as f32).unwrap();
    let mut s = m.initial_state(&kin(x(0.0).0 as f32));
    let (mut num, mut den) = (0.0, 0.0);
    for (k, r) in reference.iter().enumerate() {
        let y = f64::from(m.step(&mut s, &kin(x(k as f64 / fs).0 as f32)));
        num += (y - r) * (y - r);
        den += r * r;
    }
    (num / den).sqrt()
}

fn sine(f: f64, c: f64, amp: f64) -> impl Fn(f64) -> (f64, f64) {
    let w = 2.0 * std::f64::consts::PI * f;
    move |t| (c + amp * (w * t).sin(), amp * w * (w * t).cos())
}

/// One step per sample against a fine f64 RK4 of eq. 28 for every integrator branch
/// (n = 1, 2, general; c₂ of both signs; both asymmetry functions), at slow rates
/// where ψ matters and at 9 Hz.
#[test]
fn one_step_per_sample_matches_fine_reference() {
    let mut sets: Vec<[f32; 12]> = vec![A17, A18];
    // n = 1 and n = 2, c₂ < 0 (β > γ) and c₂ > 0, δ large enough to matter.
    sets.push([0.3, 1.0, 1.2, 1.0, 3.0, 1.0, 1.0, 0.1, 0.05, 0.0, 0.0, 1.0]);
    sets.push([0.3, 1.0, 1.2, 1.0, 1.0, 3.0, 1.0, -0.2, 0.05, 0.0, 0.0, 1.0]);
    sets.push([0.3, 1.0, 0.8, 1.0, 4.0, -1.0, 2.0, 0.0, 0.2, 4.0, 0.4, 2.0]);
    sets.push([0.3, 1.0, 0.8, 1.0, 1.0, 4.0, 2.0, 0.0, -0.1, 4.0, 0.4, 2.0]);
    sets.push([0.3, 1.0, 0.8, 2.0, 3.0, 1.0, 3.7, 0.0, 0.2, 3.0, 0.6, 2.0]);
    sets.push([0.3, 1.0, 0.8, -2.0, 3.0, 1.0, 1.3, 0.0, 0.2, 0.0, 0.6, 1.0]);
    for pr in &sets {
        for (f, fs) in [(0.05, 100.0), (1.0, 500.0), (9.0, 500.0)] {
            let samples = (2.0 * fs / f) as usize;
            let e = r_rmse(pr, &sine(f, 0.5, 0.5), fs, samples);
            eprintln!("ABW {pr:?} {f} Hz at {fs} Hz: R-RMSE {e:.2e}");
            assert!(e < 3e-3, "{pr:?} at {f} Hz / {fs} Hz: R-RMSE {e}");
        }
    }
}

#[test]
fn state_stays_bounded() {
    for pr in [A17, A18] {
        let m = BoucWenAsym::from_params(&pr, 1e-3).unwrap();
        let lim = m.z_limit();
        assert!(lim >= m.z_bar());
        let mut s = m.initial_state(&kin(0.0));
        for x in [0.0, 1e30, -1e30, 3e38, -3e38, 0.5, 0.5, 0.5, 1e-30, 0.0, 7.0] {
            for _ in 0..3 {
                let y = m.step(&mut s, &kin(x));
                assert!(s.z.abs() <= lim && s.z.is_finite(), "x={x}: z {}", s.z);
                assert!(y.is_finite() || x.abs() > 1e37);
            }
        }
        // Eq. 31 at standstill drifts (ψ ≠ 0 with sgn(0) = 0) until the limit holds it.
        let mut s = m.initial_state(&kin(0.9));
        for _ in 0..200_000 {
            m.step(&mut s, &kin(0.9));
        }
        assert!(s.z.abs() <= lim);
    }
}

/// z on the rising and falling branch of the steady loop of eq. 28 for a triangular
/// input 0 → 1 → 0 at `rate`, by f64 RK4 (independent of the model's integrator).
fn rk4_loop(pr: &[f32; 12], rate: f64) -> (Vec<f64>, Vec<f64>) {
    let p: Vec<f64> = pr.iter().map(|v| f64::from(*v)).collect();
    let (d, a, beta, gamma, n, delta) = (p[2], p[3], p[4], p[5], p[6], p[8]);
    assert_eq!(pr[11], 1.0);
    let rhs = |z: f64, x: f64, xd: f64| {
        let psi = delta * x * xd.signum();
        (a * xd - beta * xd.abs() * z.abs().powf(n - 1.0) * z - gamma * xd * z.abs().powf(n) + psi) / d
    };
    let m = LOOP_POINTS;
    let sub = 100;
    let dx = 1.0 / m as f64;
    let h = dx / rate / sub as f64;
    let mut z = p[7];
    let sweep = |z: &mut f64, up: bool, rec: &mut Vec<f64>| {
        rec.push(*z);
        for i in 0..m {
            let xd = if up { rate } else { -rate };
            let x0 = if up { i as f64 * dx } else { 1.0 - i as f64 * dx };
            for j in 0..sub {
                let x = x0 + xd * h * j as f64;
                let k1 = rhs(*z, x, xd);
                let k2 = rhs(*z + 0.5 * h * k1, x + 0.5 * h * xd, xd);
                let k3 = rhs(*z + 0.5 * h * k2, x + 0.5 * h * xd, xd);
                let k4 = rhs(*z + h * k3, x + h * xd, xd);
                *z += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
            }
            rec.push(*z);
        }
    };
    let mut scratch = Vec::new();
    for _ in 0..8 {
        sweep(&mut z, true, &mut scratch);
        sweep(&mut z, false, &mut scratch);
    }
    let (mut up, mut down) = (Vec::new(), Vec::new());
    sweep(&mut z, true, &mut up);
    sweep(&mut z, false, &mut down);
    down.reverse();
    (up, down)
}

/// The crossing detector fires for an eq. 30 set whose loop crosses (confirmed by an
/// independent f64 integration of eq. 28) and not for benign sets.
#[test]
fn crossing_detector() {
    // Eq. 30 with δ·A < 0: at rate 0.025 the asymmetry term reverses the loop in the
    // upper part of the range only (seed 004 Fig. 18a's artefact).
    let crossing = [0.3, 1.0, 1.0, 1.0, 2.0, 1.0, 1.0, 0.0, -0.05, 0.0, 0.0, 1.0];
    let m = BoucWenAsym::from_params(&crossing, 1e-3).unwrap();
    assert!(m.crossing_risk(0.0, 1.0, 0.025));
    let (up, down) = rk4_loop(&crossing, 0.025);
    let diff: Vec<f64> = up.iter().zip(&down).map(|(u, d)| d - u).collect();
    let (lo, hi) = diff.iter().fold((0.0f64, 0.0f64), |(l, h), v| (l.min(*v), h.max(*v)));
    assert!(lo < -0.01 && hi > 0.01, "reference loop does not cross: {lo} {hi}");
    // The model's loop is the reference's.
    let b = m.steady_loop(0.0, 1.0, 0.025).unwrap();
    for (i, (u, d)) in up.iter().zip(&down).enumerate() {
        assert!((f64::from(b.up[i]) - u).abs() < 2e-3 && (f64::from(b.down[i]) - d).abs() < 2e-3, "i={i}");
    }
    // Rate dependence: the same set is benign when driven fast.
    assert!(!m.crossing_risk(0.0, 1.0, 1.0));
    // Without asymmetry a classical loop never crosses.
    let mut classical = crossing;
    classical[8] = 0.0;
    let c = BoucWenAsym::from_params(&classical, 1e-3).unwrap();
    for rate in [1.0, 0.1, 0.025, 0.01] {
        assert!(!c.crossing_risk(0.0, 1.0, rate));
    }
    // Seed 004's ABW₁ and ABW₂ fits (signs as printed) at the paper's rate.
    for pr in [A17, A18] {
        assert!(!BoucWenAsym::from_params(&pr, 1e-3).unwrap().crossing_risk(0.0, 1.0, 0.1));
    }
    assert!(!m.crossing_risk(1.0, 0.0, 0.025));
    assert!(!m.crossing_risk(0.0, 1.0, 0.0));
}

#[test]
fn rejects_bad_params() {
    let m = BoucWenAsym::from_params(&A17, 1e-3).unwrap();
    let mut out = [0.0; 12];
    assert_eq!(m.write_params(&mut out), 12);
    assert_eq!(out, A17);
    for (i, v) in [
        (0, 1.5),
        (1, 0.0),
        (2, 0.0),
        (3, 0.0),
        (4, -1.0),
        (5, -17.0),
        (6, 0.5),
        (7, 1.0),
        (9, -1.0),
        (11, 3.0),
        (11, 1.5),
        (8, f32::NAN),
    ] {
        let mut bad = A17;
        bad[i] = v;
        assert!(BoucWenAsym::from_params(&bad, 1e-3).is_err(), "index {i} = {v}");
    }
    assert!(BoucWenAsym::from_params(&A17[..11], 1e-3).is_err());
    assert!(BoucWenAsym::from_params(&A17, 0.0).is_err());
}
