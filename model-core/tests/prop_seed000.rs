//! Property tests for the seed 000 models (algebraic, bouc_wen, lugre, tanh,
//! hammerstein_wiener, narx): random valid parameters and random input sequences with
//! NaN, ±Inf, ±1e30 and ordinary values through `Estimator` with each rate estimator.
//! 10,000 cases per model.
#![allow(clippy::unwrap_used, clippy::indexing_slicing)]

use std::sync::OnceLock;

use model_core::models::{algebraic, bouc_wen, hammerstein_wiener, lugre, narx, tanh};
use model_core::rate::RateParams;
use model_core::{Estimator, Finite, Flags, Model, Sample};
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

const DTS: [f32; 3] = [1.0 / 500.0, 1.0 / 1000.0, 1.0 / 3000.0];

/// Kalman gains are computed once per time step (iterating the Riccati recursion is the
/// slow part of building one).
fn kalman(i: usize) -> RateParams {
    static K: OnceLock<Vec<RateParams>> = OnceLock::new();
    K.get_or_init(|| DTS.iter().map(|dt| RateParams::kalman(*dt, 200.0, 0.01).unwrap()).collect())[i]
}

/// (dt index, rate estimator kind, filter cutoff fraction of Nyquist)
fn rate_choice() -> impl Strategy<Value = (usize, u8, f32)> {
    (0usize..3, 0u8..3, 0.05f32..0.95)
}

fn rate_params((i, kind, frac): (usize, u8, f32)) -> RateParams {
    let dt = DTS[i];
    match kind {
        0 => RateParams::backward(dt).unwrap(),
        1 => RateParams::filtered(dt, frac * 0.5 / dt).unwrap(),
        _ => kalman(i),
    }
}

fn value() -> impl Strategy<Value = f32> {
    prop_oneof![
        12 => -4.0f32..4.0,
        2 => -1.0e4f32..1.0e4,
        1 => Just(f32::NAN),
        1 => Just(f32::INFINITY),
        1 => Just(f32::NEG_INFINITY),
        1 => Just(1.0e30f32),
        1 => Just(-1.0e30f32),
    ]
}

/// A sample: input, and sometimes a measured rate (which may itself be non-finite).
fn sample() -> impl Strategy<Value = Sample> {
    (value(), prop::option::weighted(0.2, value())).prop_map(|(x, dx)| Sample { x, u: None, dx, ddx: None })
}

fn samples() -> impl Strategy<Value = Vec<Sample>> {
    prop::collection::vec(sample(), 1..64)
}

fn sample_finite(s: &Sample) -> bool {
    s.x.is_finite() && s.dx.is_none_or(f32::is_finite)
}

/// Run a sequence through the estimator and check the contract after every sample.
fn run<M: Model>(
    m: M,
    rate: RateParams,
    seq: &[Sample],
    bound: impl Fn(&M::State) -> Result<(), String>,
) -> Result<(), TestCaseError> {
    let est = Estimator::new(m, rate).unwrap();
    let mut st = est.state();
    for (i, smp) in seq.iter().enumerate() {
        let before = st;
        let out = est.step(&mut st, *smp);
        prop_assert!(out.y.is_finite(), "sample {i}: non-finite output {}", out.y);
        if sample_finite(smp) {
            prop_assert!(!out.flags.contains(Flags::NON_FINITE_INPUT), "sample {i}: flagged a finite input");
        } else {
            prop_assert!(out.flags.contains(Flags::NON_FINITE_INPUT), "sample {i}: non-finite input not flagged");
            prop_assert_eq!(out.y, before.last);
            prop_assert_eq!(st.model, before.model);
        }
        if out.flags.ok() {
            prop_assert_eq!(out.y, st.last);
        } else {
            prop_assert_eq!(out.y, before.last);
        }
        prop_assert!(st.model.is_finite(), "sample {i}: state not finite");
        if st.started {
            bound(&st.model).map_err(|e| TestCaseError::fail(format!("sample {i}: {e}")))?;
        }
    }
    Ok(())
}

fn config() -> ProptestConfig {
    ProptestConfig { cases: 10_000, failure_persistence: None, ..ProptestConfig::default() }
}

/// Replace one entry by a non-finite value.
fn poison(mut v: Vec<f32>, at: usize, which: u8) -> Vec<f32> {
    let i = at % v.len();
    v[i] = match which % 3 {
        0 => f32::NAN,
        1 => f32::INFINITY,
        _ => f32::NEG_INFINITY,
    };
    v
}

/// Valid-vector checks shared by all models: round trip, wrong length, a non-finite entry.
fn params_contract<M: Model + PartialEq>(v: &[f32], dt: f32, at: usize, which: u8) -> Result<M, TestCaseError> {
    let m = M::from_params(v, dt).map_err(|e| TestCaseError::fail(format!("valid vector rejected: {e}")))?;
    let mut out = vec![0.0f32; M::N_PARAMS];
    prop_assert_eq!(m.write_params(&mut out), M::N_PARAMS);
    prop_assert_eq!(&out[..], v);
    prop_assert_eq!(M::from_params(&out, dt).unwrap(), m);
    prop_assert!(M::from_params(&v[..v.len() - 1], dt).is_err());
    let mut longer = v.to_vec();
    longer.push(0.0);
    prop_assert!(M::from_params(&longer, dt).is_err());
    prop_assert!(M::from_params(&poison(v.to_vec(), at, which), dt).is_err());
    prop_assert!(M::from_params(v, 0.0).is_err());
    Ok(m)
}

// ---------------------------------------------------------------- algebraic

proptest! {
    #![proptest_config(config())]

    #[test]
    fn algebraic_contract(
        p in prop::collection::vec(-100.0f32..100.0, 4),
        r in rate_choice(),
        seq in samples(),
        at in 0usize..64, which in 0u8..3,
    ) {
        let m = params_contract::<algebraic::Algebraic>(&p, DTS[r.0], at, which)?;
        run(m, rate_params(r), &seq, |_| Ok(()))?;
    }
}

// ---------------------------------------------------------------- bouc_wen

/// Valid Bouc–Wen vectors: γ ≥ 0 and γ + sgn(δ)·β = t > 0.
fn bouc_wen_params() -> impl Strategy<Value = Vec<f32>> {
    (
        -10.0f32..10.0,
        prop_oneof![4 => -50.0f32..50.0, 1 => Just(0.0f32)],
        0.0f32..10.0,
        0.01f32..10.0,
        -10.0f32..10.0,
        prop_oneof![Just(1.0f32), Just(2.0f32), 1.0f32..10.0],
        -10.0f32..10.0,
        -10.0f32..10.0,
        -10.0f32..10.0,
    )
        .prop_map(|(alpha, delta, gamma, t, b_free, n, c, k, x0)| {
            let beta = if delta == 0.0 { b_free } else { delta.signum() * (t - gamma) };
            vec![alpha, beta, gamma, delta, n, c, k, x0]
        })
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn bouc_wen_contract(
        p in bouc_wen_params(),
        r in rate_choice(),
        seq in samples(),
        at in 0usize..64, which in 0u8..3,
        bad in 0u8..4,
    ) {
        let m = params_contract::<bouc_wen::BoucWen>(&p, DTS[r.0], at, which)?;
        // The analytic bound, computed here from the parameters.
        let (beta, gamma, delta, n) = (f64::from(p[1]), f64::from(p[2]), f64::from(p[3]), f64::from(p[4]));
        let zs = if delta == 0.0 { 0.0 } else { (delta.abs() / (gamma + delta.signum() * beta)).powf(1.0 / n) };
        prop_assert!((f64::from(m.z_bound()) - zs).abs() <= 1e-5 * zs);
        run(m, rate_params(r), &seq, |s: &bouc_wen::State| {
            if f64::from(s.z.abs()) <= zs * (1.0 + 1e-5) + 1e-6 { Ok(()) } else { Err(format!("|z| = {} > z* = {zs}", s.z)) }
        })?;
        // Out of bounds: γ < 0, n outside [1, 10], unbounded class (γ + sgn(δ)β ≤ 0).
        let mut q = p.clone();
        match bad {
            0 => q[2] = -0.1 - q[2].abs(),
            1 => q[4] = 0.5,
            2 => q[4] = 10.5,
            _ => { q[3] = if q[3] == 0.0 { 1.0 } else { q[3] }; q[1] = -q[3].signum() * (q[2] + 0.5); }
        }
        prop_assert!(bouc_wen::BoucWen::from_params(&q, DTS[r.0]).is_err(), "accepted {q:?}");
    }
}

// ---------------------------------------------------------------- lugre

proptest! {
    #![proptest_config(config())]

    #[test]
    fn lugre_contract(
        alpha in 0.01f32..100.0,
        rest in prop::collection::vec(-10.0f32..10.0, 5),
        r in rate_choice(),
        seq in samples(),
        at in 0usize..64, which in 0u8..3,
    ) {
        let mut p = vec![alpha];
        p.extend(rest);
        let m = params_contract::<lugre::LuGre>(&p, DTS[r.0], at, which)?;
        run(m, rate_params(r), &seq, |s: &lugre::State| {
            if s.z.abs() <= 1.0 { Ok(()) } else { Err(format!("|z| = {} > 1", s.z)) }
        })?;
        let mut q = p.clone();
        q[0] = -alpha;
        prop_assert!(lugre::LuGre::from_params(&q, DTS[r.0]).is_err());
        q[0] = 0.0;
        prop_assert!(lugre::LuGre::from_params(&q, DTS[r.0]).is_err());
    }
}

// ---------------------------------------------------------------- tanh

proptest! {
    #![proptest_config(config())]

    #[test]
    fn tanh_contract(
        p in prop::collection::vec(-10.0f32..10.0, 6),
        r in rate_choice(),
        seq in samples(),
        at in 0usize..64, which in 0u8..3,
    ) {
        let m = params_contract::<tanh::Tanh>(&p, DTS[r.0], at, which)?;
        run(m, rate_params(r), &seq, |_| Ok(()))?;
    }
}

// ---------------------------------------------------------------- hammerstein_wiener

type Hw = hammerstein_wiener::Registered;
const HW_NH: usize = 14;
const HW_NW: usize = 13;
const HW_F: usize = 3 * HW_NH + 2 + 3;
const HW_V: usize = HW_F + 5 + 3 * HW_NW + 2;

/// Denominator coefficients a₁..a₅ from 5 roots inside radius 0.98: two real, one
/// complex pair, one real.
fn stable_den() -> impl Strategy<Value = [f32; 5]> {
    (-0.98f64..0.98, -0.98f64..0.98, 0.0f64..0.98, 0.0f64..std::f64::consts::PI, -0.98f64..0.98).prop_map(
        |(r1, r2, rho, th, r5)| {
            let roots =
                [(r1, 0.0), (r2, 0.0), (rho * th.cos(), rho * th.sin()), (rho * th.cos(), -rho * th.sin()), (r5, 0.0)];
            let mut c = vec![(1.0f64, 0.0f64)];
            for (re, im) in roots {
                let mut n = vec![(0.0, 0.0); c.len() + 1];
                for (i, &(a, b)) in c.iter().enumerate() {
                    n[i].0 += a;
                    n[i].1 += b;
                    n[i + 1].0 -= a * re - b * im;
                    n[i + 1].1 -= a * im + b * re;
                }
                c = n;
            }
            [c[1].0 as f32, c[2].0 as f32, c[3].0 as f32, c[4].0 as f32, c[5].0 as f32]
        },
    )
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn hammerstein_wiener_contract(
        mut p in prop::collection::vec(-3.0f32..3.0, Hw::N_PARAMS),
        den in stable_den(),
        v_lo in -100.0f32..-0.1,
        v_hi in 0.1f32..100.0,
        r in rate_choice(),
        seq in samples(),
        at in 0usize..200, which in 0u8..3,
        unstable_at in 0usize..5,
    ) {
        p[HW_F..HW_F + 5].copy_from_slice(&den);
        p[HW_V] = v_lo;
        p[HW_V + 1] = v_hi;
        let m = params_contract::<Hw>(&p, DTS[r.0], at, which)?;
        run(m, rate_params(r), &seq, |s: &hammerstein_wiener::State| {
            if s.vs.iter().all(|v| (v_lo..=v_hi).contains(v)) { Ok(()) } else { Err(format!("v out of range: {:?}", s.vs)) }
        })?;
        // Unstable: a real pole at 1.05 (a₁ = −1.05, others 0) or a large last coefficient.
        let mut q = p.clone();
        q[HW_F..HW_F + 5].copy_from_slice(&[0.0; 5]);
        if unstable_at == 0 { q[HW_F] = -1.05; } else { q[HW_F + 4] = 1.2; }
        prop_assert!(Hw::from_params(&q, DTS[r.0]).is_err());
        let mut q = p.clone();
        q[HW_V] = v_hi + 1.0;
        prop_assert!(Hw::from_params(&q, DTS[r.0]).is_err());
        let mut q = p.clone();
        q[at % HW_F] = 2.0e6;
        prop_assert!(Hw::from_params(&q, DTS[r.0]).is_err());
    }
}

// ---------------------------------------------------------------- narx

type Nx = narx::Registered;

proptest! {
    #![proptest_config(config())]

    #[test]
    fn narx_contract(
        mut p in prop::collection::vec(-2.0f32..2.0, Nx::N_PARAMS),
        norm in (-5.0f32..5.0, 0.1f32..10.0, -5.0f32..5.0, 0.1f32..10.0),
        y_lo in -100.0f32..-1.0,
        y_hi in 1.0f32..100.0,
        r in rate_choice(),
        seq in samples(),
        at in 0usize..700, which in 0u8..3,
    ) {
        p[0] = norm.0;
        p[1] = norm.1;
        p[2] = norm.2;
        p[3] = norm.3;
        let n = Nx::N_PARAMS;
        p[n - 2] = y_lo;
        p[n - 1] = y_hi;
        let m = params_contract::<Nx>(&p, DTS[r.0], at, which)?;
        run(m, rate_params(r), &seq, |s: &narx::State| {
            if (y_lo..=y_hi).contains(&s.y) { Ok(()) } else { Err(format!("y = {} outside [{y_lo}, {y_hi}]", s.y)) }
        })?;
        let mut q = p.clone();
        q[1] = 0.0;
        prop_assert!(Nx::from_params(&q, DTS[r.0]).is_err());
        let mut q = p.clone();
        q[n - 2] = y_hi;
        prop_assert!(Nx::from_params(&q, DTS[r.0]).is_err());
    }
}
