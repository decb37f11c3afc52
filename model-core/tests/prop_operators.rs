//! Property tests of the seed 004 operator models (preisach, prandtl_ishlinskii, gpi,
//! maxwell_slip, bouc_wen_asym): random valid parameters within their bounds, random
//! inputs including NaN, ±Inf, ±1e30 and f32::MAX, through `Estimator` with each rate
//! estimator. Every case checks: no panic, finite output, the non-finite flag exactly on
//! non-finite input, the state within its analytic bound, `from_params` rejecting wrong
//! length / NaN / out-of-bound vectors and round-tripping with `write_params`.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing, clippy::panic)]

use std::sync::OnceLock;

use model_core::models::{bouc_wen_asym, gpi, maxwell_slip, prandtl_ishlinskii, preisach};
use model_core::rate::RateParams;
use model_core::{Estimator, EstimatorState, Finite, Flags, Kin, Model, Sample};
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

const CASES: u32 = 10_000;
const DTS: [f32; 2] = [1.0 / 500.0, 1.0 / 3000.0];

/// The three rate estimators at each time step (built once: the Kalman gain iterates).
fn rates(dt_index: usize) -> &'static [RateParams; 3] {
    static R: OnceLock<Vec<[RateParams; 3]>> = OnceLock::new();
    let all = R.get_or_init(|| {
        DTS.iter()
            .map(|&dt| {
                [
                    RateParams::backward(dt).unwrap(),
                    RateParams::filtered(dt, 50.0).unwrap(),
                    RateParams::kalman(dt, 200.0, 0.01).unwrap(),
                ]
            })
            .collect()
    });
    &all[dt_index]
}

fn input() -> impl Strategy<Value = f32> {
    prop_oneof![
        12 => -2.0f32..2.0,
        2 => -1e6f32..1e6,
        1 => Just(f32::NAN),
        1 => Just(f32::INFINITY),
        1 => Just(f32::NEG_INFINITY),
        1 => Just(1e30f32),
        1 => Just(-1e30f32),
        1 => Just(f32::MAX),
        1 => Just(-f32::MAX),
    ]
}

fn inputs() -> impl Strategy<Value = Vec<f32>> {
    prop::collection::vec(input(), 1..=64)
}

/// A state-bound check: model, model state, last accepted input.
type BoundCheck<'a, M> = &'a dyn Fn(&M, &<M as Model>::State, f32) -> Result<(), TestCaseError>;

/// Run `xs` through `Estimator<M>` with every rate estimator; `bound(model, state, x)`
/// checks the state after each accepted sample `x` (and after rejected ones against the
/// last accepted input).
///
/// The model is also stepped directly (no estimator, so no rollback can hide a NaN): for
/// every finite input with `|x| ≤ finite_range` its output and state must be finite.
fn run<M: Model>(
    model: &M,
    dt_index: usize,
    xs: &[f32],
    finite_range: f32,
    bound: BoundCheck<'_, M>,
) -> Result<(), TestCaseError> {
    if let Some(&x0) = xs.iter().find(|x| x.is_finite()) {
        let mut s = model.initial_state(&Kin::new(x0, 0.0, 0.0, 0.0));
        for &x in xs.iter().filter(|x| x.is_finite()) {
            let y = model.step(&mut s, &Kin::new(x, 0.0, 0.0, 0.0));
            if x.abs() <= finite_range {
                prop_assert!(y.is_finite() && s.is_finite(), "direct step: y = {y}, state {s:?} at x = {x}");
                bound(model, &s, x)?;
            }
        }
    }
    for rate in rates(dt_index) {
        let est = Estimator::new(*model, *rate).unwrap();
        let mut st: EstimatorState<M::State> = est.state();
        let mut last_x: Option<f32> = None;
        for &x in xs {
            let out = est.step(&mut st, Sample::new(x));
            prop_assert!(out.y.is_finite(), "output {} for x = {x}", out.y);
            let non_finite = !x.is_finite();
            prop_assert_eq!(out.flags.contains(Flags::NON_FINITE_INPUT), non_finite, "x = {}", x);
            if out.flags.ok() {
                last_x = Some(x);
            }
            if let Some(lx) = last_x {
                bound(model, &st.model, lx)?;
            }
        }
    }
    Ok(())
}

/// `from_params` rejects wrong lengths, a NaN anywhere and `bad` (an out-of-bound
/// vector), and round-trips `write_params`.
fn check_params<M: Model + PartialEq>(v: &[f32], dt: f32, nan_at: usize, bad: &[f32]) -> Result<M, TestCaseError> {
    prop_assert_eq!(v.len(), M::N_PARAMS);
    let m = M::from_params(v, dt).map_err(|e| TestCaseError::fail(format!("valid vector rejected: {e} {v:?}")))?;
    let mut out = vec![0.0f32; M::N_PARAMS];
    prop_assert_eq!(m.write_params(&mut out), M::N_PARAMS);
    prop_assert_eq!(&out[..], v);
    let again = M::from_params(&out, dt).unwrap();
    prop_assert!(again == m);
    prop_assert!(M::from_params(&v[..v.len() - 1], dt).is_err());
    let mut longer = v.to_vec();
    longer.push(0.0);
    prop_assert!(M::from_params(&longer, dt).is_err());
    let mut nan = v.to_vec();
    nan[nan_at % v.len()] = f32::NAN;
    prop_assert!(M::from_params(&nan, dt).is_err());
    let mut inf = v.to_vec();
    inf[nan_at % v.len()] = f32::INFINITY;
    prop_assert!(M::from_params(&inf, dt).is_err());
    prop_assert!(M::from_params(bad, dt).is_err(), "out-of-bound vector accepted: {:?}", bad);
    prop_assert!(M::from_params(v, 0.0).is_err());
    Ok(m)
}

fn with(v: &[f32], i: usize, value: f32) -> Vec<f32> {
    let mut b = v.to_vec();
    b[i] = value;
    b
}

// ---------------------------------------------------------------- prandtl_ishlinskii

type Pi = prandtl_ishlinskii::Registered;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(CASES))]
    #[test]
    fn prandtl_ishlinskii_props(
        p0 in 0.0f32..3.0,
        m0 in -1.0f32..1.0,
        r in prop::array::uniform10(0.0f32..1.0),
        p in prop::array::uniform10(0.0f32..3.0),
        xs in inputs(),
        dt_index in 0usize..2,
        nan_at in 0usize..64,
        which in 0usize..3,
        k in 0usize..10,
    ) {
        let mut v = vec![p0, m0];
        v.extend_from_slice(&r);
        v.extend_from_slice(&p);
        let bad = match which {
            0 => with(&v, 2 + k, -0.01 - r[k]),
            1 => with(&v, 12 + k, -0.01 - p[k]),
            _ => with(&v, 0, -0.01 - p0),
        };
        let m: Pi = check_params(&v, DTS[dt_index], nan_at, &bad)?;
        run(&m, dt_index, &xs, 1e6, &|m, s, x| {
            for (z, r) in s.z.iter().zip(*m.r()) {
                prop_assert!(*z >= x - r && *z <= x + r, "play output {z} outside {x} ± {r}");
            }
            Ok(())
        })?;
        // The inverse undoes the model on the ordinary part of the input.
        if p0 > 0.05 {
            let inv = m.inverse().unwrap();
            let mut s = m.initial_state(&Kin::new(0.0, 0.0, 0.0, 0.0));
            let mut si = inv.state_from(&s);
            for &x in xs.iter().filter(|x| x.abs() <= 2.0) {
                let y = m.step(&mut s, &Kin::new(x, 0.0, 0.0, 0.0));
                let xh = inv.step(&mut si, y);
                prop_assert!((xh - x).abs() <= 1e-3, "inverse {xh} vs {x}");
            }
        }
    }
}

// ---------------------------------------------------------------- gpi

type G = gpi::Registered;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(CASES))]
    #[test]
    fn gpi_props(
        envelope in 0u8..3,
        p0 in 0.0f32..2.0,
        m0 in 0.0f32..0.2,
        d1 in 0.0f32..3.0,
        d2 in 0.0f32..3.0,
        abc in prop::array::uniform6(-5.0f32..5.0),
        c_mag in prop::array::uniform2(0.01f32..5.0),
        x_min in -1.0f32..0.5,
        span in 0.1f32..2.0,
        xs in inputs(),
        dt_index in 0usize..2,
        nan_at in 0usize..64,
        which in 0usize..4,
    ) {
        let mut abc = abc;
        if envelope == 2 {
            // Gaussian envelopes need c ≠ 0: keep the sign, bound the magnitude away from 0.
            abc[2] = abc[2].signum() * c_mag[0];
            abc[5] = abc[5].signum() * c_mag[1];
        }
        let v = vec![
            p0, m0, d1, d2, abc[0], abc[1], abc[2], abc[3], abc[4], abc[5], x_min, x_min + span, f32::from(envelope),
        ];
        let bad = match which {
            0 => with(&v, 2, -0.01 - d1),
            1 => with(&v, 3, -0.01 - d2),
            2 => with(&v, 11, x_min - 0.1),
            _ => with(&v, 12, 3.0),
        };
        let m: G = check_params(&v, DTS[dt_index], nan_at, &bad)?;
        // A Gaussian envelope with c < 0 grows like exp(x²): only the estimator's
        // overflow guard can keep it finite.
        let range = if envelope == 2 && (abc[2] < 0.0 || abc[5] < 0.0) { 0.0 } else { 1e6 };
        run(&m, dt_index, &xs, range, &|m, s, x| {
            let (ar, al) = m.envelopes(x);
            if ar.is_finite() && al.is_finite() {
                for (z, r) in s.z.iter().zip(m.radii()) {
                    let (lo, hi) = ((ar - r).min(al + r), (ar - r).max(al + r));
                    prop_assert!(*z >= lo && *z <= hi, "operator {z} outside [{lo}, {hi}] at x = {x}");
                }
            }
            Ok(())
        })?;
    }
}

// ---------------------------------------------------------------- maxwell_slip

type Ms = maxwell_slip::Registered;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(CASES))]
    #[test]
    fn maxwell_slip_props(
        w0 in 0.0f32..0.2,
        k in prop::array::uniform10(0.01f32..10.0),
        f in prop::array::uniform10(0.0f32..10.0),
        k0 in -1.0f32..1.0,
        xs in inputs(),
        dt_index in 0usize..2,
        nan_at in 0usize..64,
        which in 0usize..2,
        i in 0usize..10,
    ) {
        let mut v = vec![w0];
        v.extend_from_slice(&k);
        v.extend_from_slice(&f);
        v.push(k0);
        let bad = if which == 0 { with(&v, 1 + i, -k[i]) } else { with(&v, 11 + i, -0.01 - f[i]) };
        let m: Ms = check_params(&v, DTS[dt_index], nan_at, &bad)?;
        run(&m, dt_index, &xs, 1e6, &|m, s, _x| {
            for (d, lim) in s.d.iter().zip(m.deflection_limits()) {
                prop_assert!(d.abs() <= *lim, "deflection {d} beyond f/k = {lim}");
            }
            Ok(())
        })?;
    }
}

// ---------------------------------------------------------------- preisach

type Pr = preisach::Registered;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(CASES))]
    #[test]
    fn preisach_props(
        s_hm in 0.05f32..10.0,
        m_hm in 0.0f32..20.0,
        s_hc in 0.005f32..1.0,
        m_hc in 0.0f32..0.1,
        y0 in 0.0f32..0.2,
        scale in -10.0f32..10.0,
        x_min in -1.0f32..0.5,
        span in 0.1f32..2.0,
        density in 0u8..2,
        xs in inputs(),
        dt_index in 0usize..2,
        nan_at in 0usize..64,
        which in 0usize..4,
    ) {
        let v = vec![s_hm, m_hm, s_hc, m_hc, y0, scale, x_min, x_min + span, f32::from(density)];
        let bad = match which {
            0 => with(&v, 0, -s_hm),
            1 => with(&v, 2, 0.0),
            2 => with(&v, 7, x_min),
            _ => with(&v, 8, 0.5),
        };
        let m: Pr = check_params(&v, DTS[dt_index], nan_at, &bad)?;
        // Output bounds: y₀ plus the sums of the negative / positive weights.
        let (mut neg, mut pos) = (0.0f32, 0.0f32);
        for i in 0..50 {
            for j in 0..=i {
                let w = m.weight(i, j).unwrap();
                if w < 0.0 { neg += w } else { pos += w }
            }
        }
        let tol = 1e-4 * (pos - neg).max(1.0);
        run(&m, dt_index, &xs, 1e6, &|m, s, _x| {
            prop_assert!(s.is_valid(), "not a Preisach staircase: {:?}", s.on);
            let y = m.output(s);
            prop_assert!(y >= y0 + neg - tol && y <= y0 + pos + tol, "output {y} outside the weight sums");
            Ok(())
        })?;
    }
}

// ---------------------------------------------------------------- bouc_wen_asym

type Abw = bouc_wen_asym::Registered;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(CASES))]
    #[test]
    fn bouc_wen_asym_props(
        alpha in 0.0f32..=1.0,
        kappa in 0.01f32..5.0,
        d in 0.01f32..5.0,
        a_mag in 0.01f32..5.0,
        a_neg in any::<bool>(),
        beta in 0.0f32..50.0,
        c1 in 0.01f32..50.0,
        n_kind in 0u8..3,
        n_gen in 1.0f32..8.0,
        z0_frac in -1.0f32..1.0,
        delta in -5.0f32..5.0,
        p in 0.0f32..2.0,
        q in 0.0f32..1.0,
        variant in 1u8..3,
        xs in inputs(),
        dt_index in 0usize..2,
        nan_at in 0usize..64,
        which in 0usize..5,
    ) {
        let sa = if a_neg { -1.0f32 } else { 1.0 };
        let a = sa * a_mag;
        // γ so that β + γ·sgn(A) = c₁ > 0.
        let gamma = sa * (c1 - beta);
        let n = match n_kind { 0 => 1.0, 1 => 2.0, _ => n_gen };
        let c2 = sa * gamma - beta;
        let zrun = if c2 > 0.0 { (a_mag / c2).powf(1.0 / n) } else { f32::INFINITY };
        let z0 = z0_frac * 0.2f32.min(0.99 * zrun);
        let v = vec![alpha, kappa, d, a, beta, gamma, n, z0, delta, p, q, f32::from(variant)];
        let bad = match which {
            0 => with(&v, 0, 1.0 + alpha.max(0.01)),
            1 => with(&v, 4, -0.01 - beta),
            2 => with(&v, 6, 0.99),
            3 => with(&v, 3, 0.0),
            _ => with(&v, 11, 0.0),
        };
        let m: Abw = check_params(&v, DTS[dt_index], nan_at, &bad)?;
        let lim = m.z_limit();
        prop_assert!(lim >= m.z_bar() && lim >= z0.abs());
        run(&m, dt_index, &xs, 1e6, &|_m, s, _x| {
            prop_assert!(s.z.abs() <= lim, "|z| = {} beyond z_lim = {lim}", s.z.abs());
            Ok(())
        })?;
    }
}
