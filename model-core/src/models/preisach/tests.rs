#![allow(clippy::unwrap_used, clippy::indexing_slicing)]
use super::*;

fn kin(x: f32) -> Kin {
    Kin::new(x, 0.0, 0.0, 0.0)
}

/// Seed 004 Table A2 (GC-50).
fn gc50() -> Preisach<50> {
    Preisach::new(Density::GaussCauchy, 3.2352, 11.6040, 0.0232, 0.0001, 0.0837, 1.0, 0.0, 1.0, 1e-3).unwrap()
}

/// Eq. 9 by hand for a 2 × 2 grid: thresholds 0.25 and 0.75, relays
/// (0.25, 0.25), (0.75, 0.25), (0.75, 0.75).
#[test]
fn matches_eq9_by_hand() {
    let (sm, mm, sc, mc, y0, s) = (0.3f64, 0.4f64, 0.2f64, 0.1f64, 0.05f64, 2.0f64);
    let g = |k: f64, mu: f64, sg: f64| {
        (-(k - mu) * (k - mu) / (2.0 * sg * sg)).exp() / ((2.0 * std::f64::consts::PI).sqrt() * sg)
    };
    let c = |k: f64, mu: f64, sg: f64| 1.0 / (std::f64::consts::PI * sg * (1.0 + ((k - mu) / sg).powi(2)));
    for density in [Density::GaussGauss, Density::GaussCauchy] {
        let pc = |hc: f64| if density == Density::GaussGauss { g(hc, mc, sc) } else { c(hc, mc, sc) };
        let w11 = g(0.25, mm, sm) * pc(0.0);
        let w21 = g(0.5, mm, sm) * pc(0.25);
        let w22 = g(0.75, mm, sm) * pc(0.0);
        let m = Preisach::<2>::new(density, 0.3, 0.4, 0.2, 0.1, 0.05, 2.0, 0.0, 1.0, 1e-3).unwrap();
        assert_eq!(m.thresholds(), &[0.25, 0.75]);
        let mut st = m.initial_state(&kin(0.0));
        let seq = [
            (0.0, 0.0),
            (0.5, w11),
            (1.0, w11 + w21 + w22),
            (0.5, w11 + w21),
            (0.2, 0.0),
            (0.8, w11 + w21 + w22),
            (0.25, w11),
        ];
        for (x, w) in seq {
            let y = f64::from(m.step(&mut st, &kin(x)));
            let want = y0 + s * w;
            assert!((y - want).abs() < 1e-5 * want.abs().max(1.0), "{density:?} x={x}: {y} vs {want}");
            assert!(st.is_valid());
        }
    }
}

#[test]
fn range_mapping_and_weights() {
    let m = Preisach::<4>::new(Density::GaussGauss, 0.5, 0.5, 0.1, 0.0, 0.0, 1.0, 100.0, 300.0, 1e-3).unwrap();
    assert_eq!(m.thresholds(), &[125.0, 175.0, 225.0, 275.0]);
    assert!(m.weight(1, 2).is_none() && m.weight(4, 0).is_none());
    // Relay (α₄, β₁) = (0.875, 0.125) normalised: H_M = 0.5, H_C = 0.375.
    let g = |k: f64, mu: f64, sg: f64| {
        (-(k - mu) * (k - mu) / (2.0 * sg * sg)).exp() / ((2.0 * std::f64::consts::PI).sqrt() * sg)
    };
    let want = g(0.5, 0.5, 0.5) * g(0.375, 0.0, 0.1);
    let got = f64::from(m.weight(3, 0).unwrap());
    assert!((got - want).abs() < 1e-5 * want, "{got} vs {want}");
}

/// Run `xs` (each value reached by a straight ramp of small steps) and return the
/// final state and the outputs at every sample.
fn run(m: &Preisach<50>, s: &mut State<50>, xs: &[f32]) -> Vec<f32> {
    let mut out = Vec::new();
    let mut x0 = xs[0];
    for &x1 in xs {
        for k in 1..=40 {
            let x = x0 + (x1 - x0) * k as f32 / 40.0;
            out.push(m.step(s, &kin(x)));
        }
        x0 = x1;
    }
    out
}

/// Wiping-out: once the input passes a dominant maximum and then a dominant minimum,
/// the smaller extrema in between are forgotten; two histories sharing those last
/// dominant extrema give identical outputs from then on.
#[test]
fn wiping_out_property() {
    let m = gc50();
    let mut a = m.initial_state(&kin(0.0));
    let mut b = m.initial_state(&kin(0.0));
    // Different inner histories, same dominant max 0.85 and dominant min 0.12.
    run(&m, &mut a, &[0.0, 0.6, 0.3, 0.85, 0.4, 0.7, 0.5, 0.12]);
    run(&m, &mut b, &[0.0, 0.85, 0.2, 0.8, 0.35, 0.6, 0.15, 0.12]);
    assert_eq!(a, b, "memory of the smaller extrema was not wiped out");
    let cont = [0.12, 0.55, 0.3, 0.72, 0.05, 0.9];
    let ya = run(&m, &mut a, &cont);
    let yb = run(&m, &mut b, &cont);
    assert_eq!(ya, yb);
    // Control: a history with a different dominant maximum does not coincide.
    let mut c = m.initial_state(&kin(0.0));
    run(&m, &mut c, &[0.0, 0.95, 0.4, 0.12]);
    assert_ne!(a, c);
    let yc = run(&m, &mut c, &cont);
    assert!(ya.iter().zip(&yc).any(|(p, q)| (p - q).abs() > 1e-4));
}

/// Congruency: minor loops between the same two input extrema are congruent (equal up
/// to a vertical shift) whatever the history before them.
#[test]
fn congruency_property() {
    let m = gc50();
    let (lo, hi) = (0.3f32, 0.62f32);
    let loops: Vec<Vec<f32>> = [vec![0.0, 1.0, lo], vec![0.0, 0.7, 0.05, 0.66, lo], vec![0.0, 0.9, 0.1, hi, lo]]
        .iter()
        .map(|hist| {
            let mut s = m.initial_state(&kin(0.0));
            run(&m, &mut s, hist);
            // One cycle lo → hi → lo to settle, then record the next.
            run(&m, &mut s, &[lo, hi, lo]);
            run(&m, &mut s, &[lo, hi, lo])
        })
        .collect();
    let mut shifts = Vec::new();
    for other in &loops[1..] {
        let d: Vec<f32> = loops[0].iter().zip(other).map(|(p, q)| q - p).collect();
        let spread = d.iter().cloned().fold(f32::MIN, f32::max) - d.iter().cloned().fold(f32::MAX, f32::min);
        assert!(spread < 1e-4, "minor loops not congruent: spread {spread}");
        shifts.push(d[0]);
    }
    // The histories do put the loops at different heights (the test is not vacuous).
    assert!(shifts.iter().all(|s| s.abs() > 1e-3), "shifts {shifts:?}");
    // And the minor loop is a loop: rising and falling branches differ mid-way.
    let l = &loops[0];
    let n = l.len();
    assert!((l[n / 4] - l[3 * n / 4]).abs() > 1e-3);
}

#[test]
fn state_validity_and_demagnetised() {
    let m = Preisach::<8>::new(Density::GaussGauss, 1.0, 0.5, 0.2, 0.0, 0.0, 1.0, 0.0, 1.0, 1e-3).unwrap();
    let d = m.demagnetised_state();
    assert!(d.is_valid());
    // Row i: thresholds (i+½)/8, relays with αᵢ + βⱼ < 1 → j < 7 − i.
    assert_eq!(d.on, [1, 2, 3, 4, 3, 2, 1, 0]);
    assert!(!State { on: [0, 0, 0, 0, 0, 0, 0, 2] }.is_valid());
    assert!(!State { on: [2, 0, 0, 0, 0, 0, 0, 0] }.is_valid());
    assert!(State { on: [1, 2, 2, 2, 1, 1, 1, 0] }.is_valid());
}

#[test]
fn rejects_bad_params() {
    let ok = [3.2, 11.6, 0.023, 0.0, 0.08, 1.0, 0.0, 1.0, 1.0];
    let m = Preisach::<10>::from_params(&ok, 1e-3).unwrap();
    let mut out = [0.0; 9];
    assert_eq!(m.write_params(&mut out), 9);
    assert_eq!(out, ok);
    for (i, v) in [(0, 0.0), (2, -1.0), (7, 0.0), (8, 2.0), (8, 0.5), (4, f32::NAN), (5, f32::INFINITY)] {
        let mut bad = ok;
        bad[i] = v;
        assert!(Preisach::<10>::from_params(&bad, 1e-3).is_err(), "index {i} = {v}");
    }
    // Tiny σ_HC makes the Cauchy peak overflow f32 once scaled.
    let mut huge = ok;
    huge[5] = 1e30;
    huge[2] = 1e-30;
    assert!(Preisach::<10>::from_params(&huge, 1e-3).is_err());
    assert!(Preisach::<10>::from_params(&ok[..8], 1e-3).is_err());
}

#[test]
fn built_in_place_equals_the_value_from_params() {
    let sets: [[f32; 9]; 3] = [
        [3.2352, 11.6040, 0.0232, 0.0001, 0.0837, 1.0, 0.0, 1.0, 1.0],
        [1.0, 2.0, 0.1, 0.05, 0.1, 1.0, -1.0, 1.0, 0.0],
        [0.3, 0.5, 0.2, 0.1, -0.4, 2.5, -2.0, 3.0, 0.0],
    ];
    // A slot that held another model (and a failed build) before each build.
    let mut slot = Preisach::<50>::ZEROED;
    for (k, p) in sets.iter().enumerate() {
        let dt = 1e-4 * (k + 1) as f32;
        assert!(slot.rebuild_from_params(&[0.0; 9], dt).is_err());
        // Fails after part of the table is written (the Cauchy peak overflows f32).
        assert!(slot.rebuild_from_params(&[3.2, 11.6, 1e-30, 0.0, 0.08, 1e30, 0.0, 1.0, 1.0], dt).is_err());
        slot.rebuild_from_params(p, dt).unwrap();
        let by_value = Preisach::<50>::from_params(p, dt).unwrap();
        assert_eq!(slot, by_value, "set {k}");
        let (mut a, mut b) = (State::default(), State::default());
        for x in [-1.0, 0.3, 0.9, -0.2, 0.5, 2.0] {
            assert_eq!(slot.step(&mut a, &kin(x)).to_bits(), by_value.step(&mut b, &kin(x)).to_bits());
        }
    }
    assert!(slot.rebuild_from_params(&sets[0][..8], 1e-3).is_err());
}
