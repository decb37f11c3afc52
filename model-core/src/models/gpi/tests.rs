#![allow(clippy::unwrap_used, clippy::indexing_slicing)]
use super::*;

fn kin(x: f32) -> Kin {
    Kin::new(x, 0.0, 0.0, 0.0)
}

/// Seed 004 Table A9 (tanh envelopes, 10 operators), signs as printed.
fn table_a9() -> Gpi<10> {
    Gpi::new(
        Envelope::Tanh,
        0.4084,
        0.1185,
        0.1872,
        0.1920,
        EnvelopeCoeffs::new(1.2251, 0.5371, 0.2911),
        EnvelopeCoeffs::new(2.1285, 1.9745, 1.7202),
        0.0,
        1.0,
        1e-3,
    )
    .unwrap()
}

#[test]
fn radii_weights_and_envelopes_by_hand() {
    let m = table_a9();
    assert!((m.radii()[0]).abs() < 1e-7 && (m.radii()[9] - 1.0).abs() < 1e-6);
    assert!((m.radii()[3] - 1.0 / 3.0).abs() < 1e-6);
    let want = 0.1872 * (-0.1920f64 / 3.0).exp();
    assert!((f64::from(m.weights()[3]) - want).abs() < 1e-6);
    let (ar, al) = m.envelopes(0.3);
    assert!((f64::from(ar) - (1.2251 * (0.8371f64).tanh() + 0.2911)).abs() < 1e-5);
    assert!((f64::from(al) - (2.1285 * (2.2745f64).tanh() + 1.7202)).abs() < 1e-5);
    let poly = Gpi::<3>::new(
        Envelope::Polynomial,
        0.0,
        0.0,
        1.0,
        0.0,
        EnvelopeCoeffs::new(0.7144, 0.3616, 0.0),
        EnvelopeCoeffs::new(0.8169, 0.4579, 0.0),
        0.0,
        1.0,
        1e-3,
    )
    .unwrap();
    let (ar, _) = poly.envelopes(0.5);
    assert!((ar - (0.25 + 0.3572 + 0.3616)).abs() < 1e-6);
    let gauss = Gpi::<3>::new(
        Envelope::Gaussian,
        0.0,
        0.0,
        1.0,
        0.0,
        EnvelopeCoeffs::new(4.9515, 1.6332, 2.3430),
        EnvelopeCoeffs::new(2.8279, 1.2269, 4.6150),
        0.0,
        1.0,
        1e-3,
    )
    .unwrap();
    let (ar, al) = gauss.envelopes(0.5);
    let want_r = 4.9515 * (-(0.5f64 - 1.6332).powi(2) / (2.0 * 2.3430)).exp();
    let want_l = 2.8279 * (-(0.5f64 - 1.2269).powi(2) / (2.0 * 4.6150)).exp();
    assert!((f64::from(ar) - want_r).abs() < 1e-5 && (f64::from(al) - want_l).abs() < 1e-5);
}

/// Eq. 16–18 by hand for two operators with polynomial envelopes.
#[test]
fn operator_by_hand() {
    // α_R = x² + 0·x − 0.1, α_L = x² + 0·x + 0.1; radii 0 and 1; weights 1, e^{-1}.
    let m = Gpi::<2>::new(
        Envelope::Polynomial,
        0.5,
        0.0,
        1.0,
        1.0,
        EnvelopeCoeffs::new(0.0, -0.1, 0.0),
        EnvelopeCoeffs::new(0.0, 0.1, 0.0),
        0.0,
        1.0,
        1e-3,
    )
    .unwrap();
    let mut s = m.initial_state(&kin(0.0));
    // x=0: op1 in [−0.1, 0.1] from M0 = 0 → 0; op2 in [−1.1, 1.1] → 0.
    assert_eq!(s.z, [0.0, 0.0]);
    // x = 0.8: α_R = 0.54, α_L = 0.74 → op1 = 0.54, op2 = max(−0.46, min(1.74, 0)) = 0
    let y = m.step(&mut s, &kin(0.8));
    assert!((y - (0.4 + 0.54)).abs() < 1e-6, "{y}");
    // x = 0.5: α_R = 0.15, α_L = 0.35 → op1 = min(0.35, 0.54) = 0.35
    let y = m.step(&mut s, &kin(0.5));
    assert!((y - (0.25 + 0.35)).abs() < 1e-6, "{y}");
}

/// One period of the steady loop for `x = c + a·sin`.
fn steady_loop(m: &Gpi<10>, c: f32, a: f32, n: usize) -> Vec<f32> {
    let x = |i: usize| c + a * (2.0 * core::f32::consts::PI * (i % n) as f32 / n as f32).sin();
    let mut s = m.initial_state(&kin(x(0)));
    let mut ys = Vec::new();
    for i in 0..4 * n {
        ys.push(m.step(&mut s, &kin(x(i))));
    }
    ys.split_off(3 * n)
}

/// Point-symmetry defect of a loop: max |y(t) + y(t+T/2) − 2ȳ| / range.
fn asymmetry(y: &[f32]) -> f32 {
    let n = y.len();
    let yc = y.iter().sum::<f32>() / n as f32;
    let range = y.iter().cloned().fold(f32::MIN, f32::max) - y.iter().cloned().fold(f32::MAX, f32::min);
    (0..n / 2).map(|i| (y[i] + y[i + n / 2] - 2.0 * yc).abs()).fold(0.0, f32::max) / range
}

/// Seed 004 Table A11 (polynomial envelopes, 10 operators), signs as printed.
fn table_a11() -> Gpi<10> {
    Gpi::new(
        Envelope::Polynomial,
        0.1060,
        0.0485,
        0.1752,
        2.7863,
        EnvelopeCoeffs::new(0.7144, 0.3616, 0.0),
        EnvelopeCoeffs::new(0.8169, 0.4579, 0.0),
        0.0,
        1.0,
        1e-3,
    )
    .unwrap()
}

/// Different loading/unloading envelopes give a loop that is not point-symmetric;
/// the same odd envelope on both sides gives a point-symmetric one.
#[test]
fn asymmetry_enters_through_the_envelopes() {
    let y = steady_loop(&table_a11(), 0.5, 0.5, 400);
    let asym = asymmetry(&y);
    assert!(asym > 0.05, "asymmetric GPI loop index {asym}");
    let width = (y[0] - y[200]).abs();
    assert!(width > 0.01, "asymmetric loop width {width}");

    // Symmetric configuration: α_R = α_L = tanh(x − 0.5), odd about the centre 0.5.
    let e = EnvelopeCoeffs::new(1.0, -0.5, 0.0);
    let sym = Gpi::<10>::new(Envelope::Tanh, 0.4, 0.0, 0.5, 0.5, e, e, 0.0, 1.0, 1e-3).unwrap();
    let y = steady_loop(&sym, 0.5, 0.5, 400);
    let s = asymmetry(&y);
    eprintln!("GPI asymmetry index: Table A11 {asym:.4}, symmetric tanh {s:.2e}");
    assert!(s < 1e-3, "symmetric GPI loop index {s}");
    // …and it really is a loop (non-zero width), not a single curve.
    let width = (y[0] - y[200]).abs();
    assert!(width > 0.01, "loop width {width}");
}

#[test]
fn order_preservation_check() {
    assert!(table_a9().order_preserving(101));
    let bad = Gpi::<2>::new(
        Envelope::Polynomial,
        0.0,
        0.0,
        1.0,
        0.0,
        EnvelopeCoeffs::new(0.0, 0.2, 0.0),
        EnvelopeCoeffs::new(0.0, 0.0, 0.0),
        0.0,
        1.0,
        1e-3,
    )
    .unwrap();
    assert!(!bad.order_preserving(11));
}

#[test]
fn rejects_bad_params() {
    let ok = [0.4, 0.1, 0.2, 0.2, 1.2, 0.5, 0.3, 2.1, 1.9, 1.7, 0.0, 1.0, 1.0];
    let m = Gpi::<10>::from_params(&ok, 1e-3).unwrap();
    let mut out = [0.0; 13];
    assert_eq!(m.write_params(&mut out), 13);
    assert_eq!(out, ok);
    for (i, v) in [(2, -0.1), (3, -1.0), (10, 2.0), (12, 3.0), (12, 0.5), (0, f32::NAN)] {
        let mut bad = ok;
        bad[i] = v;
        assert!(Gpi::<10>::from_params(&bad, 1e-3).is_err(), "index {i} = {v}");
    }
    let mut gauss0 = ok;
    gauss0[12] = 2.0;
    gauss0[6] = 0.0;
    assert!(Gpi::<10>::from_params(&gauss0, 1e-3).is_err());
    assert!(Gpi::<10>::from_params(&ok[..12], 1e-3).is_err());
}
