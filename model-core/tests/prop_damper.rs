//! Property tests of the damper models (seeds 001–003): `bingham`, `spencer`, `dahl`,
//! `arctan`, `arctan_inertia`, `trig`.
//!
//! Per model, 10 000 cases of random valid parameters and ≤ 64 random samples whose input,
//! command and measured rate mix NaN, ±Inf, ±1e30 and ordinary values, run through
//! `model_core::Estimator` with each rate estimator: no panic, output always finite, the
//! non-finite-input flag exactly on non-finite samples (with the last output held), held
//! output on overflow, and the state within its analytic bound. The same cases check that
//! `from_params` accepts the vector, round-trips through `write_params`, and rejects a wrong
//! length, a NaN / ±Inf anywhere, and an out-of-bound value.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing, clippy::panic)]

use std::sync::OnceLock;

use model_core::estimator::Flags;
use model_core::models::{arctan, arctan_inertia, bingham, dahl, spencer, trig};
use model_core::rate::RateParams;
use model_core::{Estimator, Finite, Model, ParamError, Sample};
use proptest::prelude::*;

const CASES: u32 = 10_000;
const DTS: [f32; 3] = [1.0 / 3000.0, 1.0 / 500.0, 1.0 / 100.0];

/// The three rate estimators for each time step (built once: the Kalman gain iterates).
fn rates() -> &'static [[RateParams; 3]; 3] {
    static R: OnceLock<[[RateParams; 3]; 3]> = OnceLock::new();
    R.get_or_init(|| {
        DTS.map(|dt| {
            [
                RateParams::backward(dt).unwrap(),
                RateParams::filtered(dt, 0.05 / dt).unwrap(),
                RateParams::kalman(dt, 200.0, 0.01).unwrap(),
            ]
        })
    })
}

/// A value that is sometimes NaN, ±Inf or ±1e30, mostly ordinary (large and small moves).
fn value() -> impl Strategy<Value = f32> {
    prop_oneof![
        6 => -10.0f32..10.0,
        3 => -0.05f32..0.05,
        1 => Just(f32::NAN),
        1 => Just(f32::INFINITY),
        1 => Just(f32::NEG_INFINITY),
        1 => Just(1e30f32),
        1 => Just(-1e30f32),
    ]
}

/// Commands: mostly in a driver's range, sometimes hostile.
fn command() -> impl Strategy<Value = f32> {
    prop_oneof![8 => -0.5f32..3.0, 4 => value()]
}

fn samples() -> impl Strategy<Value = Vec<Sample>> {
    let one = (value(), command(), prop::option::weighted(0.15, value()), prop::option::weighted(0.1, value()))
        .prop_map(|(x, u, dx, ddx)| Sample { x, u: Some(u), dx, ddx });
    prop::collection::vec(one, 1..=64)
}

/// Unit draws mapped onto parameter ranges.
fn unit(n: usize) -> impl Strategy<Value = Vec<f32>> {
    prop::collection::vec(0.0f32..=1.0, n)
}
fn lerp(a: f32, b: f32, t: f32) -> f32 {
    a + (b - a) * t
}
fn logu(a: f32, b: f32, t: f32) -> f32 {
    a * (b / a).powf(t)
}

/// Run the samples through an Estimator and check the output/flag/bound rules.
fn run<M: Model>(
    model: M,
    rate: RateParams,
    samples: &[Sample],
    bound: impl Fn(&M::State) -> bool,
) -> Result<(), TestCaseError> {
    let est = Estimator::new(model, rate).unwrap();
    let mut s = est.state();
    let mut last = 0.0f32;
    for sample in samples {
        let out = est.step(&mut s, *sample);
        prop_assert!(out.y.is_finite(), "non-finite output for {sample:?}");
        let finite_in = sample.x.is_finite()
            && sample.u.is_none_or(f32::is_finite)
            && sample.dx.is_none_or(f32::is_finite)
            && sample.ddx.is_none_or(f32::is_finite);
        if finite_in {
            prop_assert!(!out.flags.contains(Flags::NON_FINITE_INPUT));
            if out.flags.contains(Flags::OVERFLOW) {
                prop_assert_eq!(out.y, last);
            }
        } else {
            prop_assert_eq!(out.flags, Flags(Flags::NON_FINITE_INPUT));
            prop_assert_eq!(out.y, last);
        }
        prop_assert!(s.model.is_finite());
        prop_assert!(bound(&s.model), "state out of bound: {:?}", s.model);
        last = out.y;
    }
    Ok(())
}

/// `from_params` / `write_params` round trip and rejections.
fn params<M: Model + PartialEq>(
    flat: &[f32],
    dt: f32,
    pick: usize,
    out_of_bound: (usize, f32),
) -> Result<M, TestCaseError> {
    prop_assert_eq!(flat.len(), M::N_PARAMS);
    prop_assert_eq!(M::PARAM_NAMES.len(), M::N_PARAMS);
    let m = M::from_params(flat, dt).map_err(|e| TestCaseError::fail(format!("{e} for {flat:?}")))?;
    let mut back = vec![0.0f32; M::N_PARAMS];
    prop_assert_eq!(m.write_params(&mut back), M::N_PARAMS);
    prop_assert_eq!(&back[..], flat);
    prop_assert!(M::from_params(&back, dt).unwrap() == m);
    let short = &flat[..M::N_PARAMS - 1];
    let wrong = matches!(M::from_params(short, dt), Err(ParamError::WrongCount { .. }));
    prop_assert!(wrong, "short vector not rejected");
    let mut long = flat.to_vec();
    long.push(1.0);
    let wrong = matches!(M::from_params(&long, dt), Err(ParamError::WrongCount { .. }));
    prop_assert!(wrong, "long vector not rejected");
    let i = pick % M::N_PARAMS;
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let mut v = flat.to_vec();
        v[i] = bad;
        prop_assert!(M::from_params(&v, dt).is_err(), "{} = {bad} accepted", M::PARAM_NAMES[i]);
    }
    let mut v = flat.to_vec();
    v[out_of_bound.0] = out_of_bound.1;
    prop_assert!(M::from_params(&v, dt).is_err(), "{} = {} accepted", M::PARAM_NAMES[out_of_bound.0], out_of_bound.1);
    prop_assert!(M::from_params(flat, 0.0).is_err());
    prop_assert!(M::from_params(flat, f32::NAN).is_err());
    Ok(m)
}

fn spencer_flat(t: &[f32]) -> Vec<f32> {
    let gamma = logu(1.0, 1e3, t[9]);
    let n = if t[12] < 0.3 {
        1.0
    } else if t[12] < 0.7 {
        2.0
    } else {
        lerp(1.0, 4.0, t[12])
    };
    vec![
        logu(0.1, 1e3, t[0]),
        lerp(0.0, 50.0, t[1]),
        lerp(0.0, 500.0, t[2]),
        logu(1.0, 1e4, t[3]),
        lerp(0.0, 50.0, t[4]),
        lerp(-50.0, 50.0, t[5]),
        lerp(-20.0, 20.0, t[6]),
        lerp(0.0, 2000.0, t[7]),
        lerp(0.0, 2000.0, t[8]),
        gamma,
        lerp(-0.99 * gamma, 1e3, t[10]),
        logu(1.0, 1e3, t[11]),
        n,
        logu(1.0, 1e3, t[13]),
    ]
}

fn dahl_flat(t: &[f32]) -> Vec<f32> {
    vec![
        lerp(0.0, 100.0, t[0]),
        lerp(0.0, 50.0, t[1]),
        lerp(0.0, 1e3, t[2]),
        lerp(0.0, 1e3, t[3]),
        lerp(-50.0, 50.0, t[4]),
        logu(0.1, 1e3, t[5]),
        lerp(-100.0, 100.0, t[6]),
        logu(1.0, 1e3, t[7]),
    ]
}

fn bingham_flat(t: &[f32]) -> Vec<f32> {
    let mut v: Vec<f32> = t.iter().map(|t| lerp(-1e3, 1e3, *t)).collect();
    v[0] = lerp(0.0, 1e3, t[0]);
    v[4] = lerp(0.0, 100.0, t[4]);
    for c in &mut v[5..9] {
        *c *= 0.1;
    }
    v
}

fn arctan_flat(t: &[f32]) -> Vec<f32> {
    vec![
        lerp(-100.0, 100.0, t[0]),
        lerp(-100.0, 100.0, t[1]),
        lerp(0.0, 1e3, t[2]),
        lerp(-100.0, 100.0, t[3]),
        lerp(0.0, 1e3, t[4]),
        lerp(-1e3, 1e3, t[5]),
        lerp(0.0, 100.0, t[6]),
        lerp(-10.0, 10.0, t[7]),
        lerp(0.0, 1.0, t[8]),
        lerp(-0.1, 0.1, t[9]),
    ]
}

/// Quadratics that satisfy the sign structure over 0–2 A by construction
/// (non-negative P1, P2 for D, B, k, c; C ≤ 1 + 0.25·2 + 0.125·4 = 2).
fn trig_flat(t: &[f32]) -> Vec<f32> {
    let nonneg = |t0: f32, t1: f32, t2: f32, s: f32| [lerp(0.0, s, t0), lerp(0.0, s, t1), lerp(0.0, s / 4.0, t2)];
    let [d, c, b, sh, sv, k, cv] = [0, 3, 6, 9, 12, 15, 18].map(|i| (t[i], t[i + 1], t[i + 2]));
    let mut v = Vec::with_capacity(21);
    v.extend(nonneg(d.0, d.1, d.2, 2.0));
    v.extend([lerp(0.0, 1.0, c.0), lerp(0.0, 0.25, c.1), lerp(0.0, 0.125, c.2)]);
    v.extend(nonneg(b.0, b.1, b.2, 0.1));
    v.extend([lerp(-20.0, 20.0, sh.0), lerp(-20.0, 20.0, sh.1), lerp(-10.0, 10.0, sh.2)]);
    v.extend([lerp(-1.0, 1.0, sv.0), lerp(-1.0, 1.0, sv.1), lerp(-1.0, 1.0, sv.2)]);
    v.extend(nonneg(k.0, k.1, k.2, 2.0));
    v.extend(nonneg(cv.0, cv.1, cv.2, 0.001));
    v
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(CASES))]

    #[test]
    fn spencer_properties(t in unit(14), dti in 0usize..3, ri in 0usize..3, pick in 0usize..64, xs in samples()) {
        let dt = DTS[dti];
        let flat = spencer_flat(&t);
        let m: spencer::Spencer = params(&flat, dt, pick, (12, 0.5))?;
        let bound = m.z_max() * (1.0 + 1e-5);
        run(m, rates()[dti][ri], &xs, |s: &spencer::State| s.z.abs() <= bound)?;
    }

    #[test]
    fn dahl_properties(t in unit(8), dti in 0usize..3, ri in 0usize..3, pick in 0usize..64, xs in samples()) {
        let dt = DTS[dti];
        let flat = dahl_flat(&t);
        let m: dahl::Dahl = params(&flat, dt, pick, (5, -1.0))?;
        run(m, rates()[dti][ri], &xs, |s: &dahl::State| s.z.abs() <= 1.0)?;
    }

    #[test]
    fn bingham_properties(t in unit(10), dti in 0usize..3, ri in 0usize..3, pick in 0usize..64, xs in samples()) {
        let dt = DTS[dti];
        let flat = bingham_flat(&t);
        let m: bingham::Bingham = params(&flat, dt, pick, (0, -1.0))?;
        run(m, rates()[dti][ri], &xs, |_: &()| true)?;
    }

    #[test]
    fn arctan_properties(t in unit(10), dti in 0usize..3, ri in 0usize..3, pick in 0usize..64, xs in samples()) {
        let dt = DTS[dti];
        let flat = arctan_flat(&t);
        let m: arctan::Arctan = params(&flat, dt, pick, (4, -1.0))?;
        run(m, rates()[dti][ri], &xs, |_: &()| true)?;
    }

    #[test]
    fn arctan_inertia_properties(t in unit(11), dti in 0usize..3, ri in 0usize..3, pick in 0usize..64, xs in samples()) {
        let dt = DTS[dti];
        let mut flat = arctan_flat(&t);
        flat.push(lerp(-10.0, 10.0, t[10]));
        let m: arctan_inertia::ArctanInertia = params(&flat, dt, pick, (6, -1.0))?;
        run(m, rates()[dti][ri], &xs, |_: &()| true)?;
    }

    #[test]
    fn trig_properties(t in unit(21), dti in 0usize..3, ri in 0usize..3, pick in 0usize..64, xs in samples()) {
        let dt = DTS[dti];
        let flat = trig_flat(&t);
        let m: trig::Trig = params(&flat, dt, pick, (3, 2.5))?;
        run(m, rates()[dti][ri], &xs, |_: &()| true)?;
    }
}
