#![allow(clippy::unwrap_used, clippy::indexing_slicing)]
use super::*;

/// Eq. 10–12 with eq. 31–37 at i = 0.6 A by hand.
#[test]
fn matches_eq10_to_12_with_seed002_polynomials() {
    let m = Trig::new(SEED002, 1e-3).unwrap();
    let i = 0.6f32;
    let d = -0.8226 * i * i + 2.1713 * i + 0.1532;
    let c = -0.7485 * i * i + 1.6884 * i + 0.5544;
    let b = 0.0047 * i * i - 0.0101 * i + 0.0125;
    let sh = -8.1556 * i * i + 20.321 * i - 9.452;
    let sv = -0.0726 * i * i + 0.1931 * i + 0.0397;
    let k = 0.4617 * i * i - 1.0508 * i + 1.1351;
    let cv = 0.0005 * i + 0.0007;
    for (v, a) in [(40.0f32, 100.0f32), (40.0, -100.0), (-120.0, 5.0), (0.0, 0.0)] {
        let sg = if a > 0.0 {
            1.0
        } else if a < 0.0 {
            -1.0
        } else {
            0.0
        };
        let bv = b * (v + sh);
        let phi = bv + 0.1 * bv.atan();
        let want = d * (c * (phi - k * sg).atan()).sin() + cv * v + sv;
        let y = m.step(&mut (), &Kin::new(0.0, v, a, i));
        assert!((y - want).abs() < 1e-5, "v {v} a {a}: {y} vs {want}");
    }
}

/// Constant form (P1 = P2 = 0) ignores the command; bounds of the sign structure.
#[test]
fn constant_form_and_bounds() {
    let mut flat = [0.0f32; 21];
    for (blk, v) in [0.18f32, 0.85, 0.05, -3.0, 0.2, 1.0, 0.0003].iter().enumerate() {
        flat[3 * blk] = *v;
    }
    let m = Trig::from_params(&flat, 1e-3).unwrap();
    let k = Kin::new(0.0, 25.0, -3.0, 0.0);
    assert_eq!(m.step(&mut (), &k), m.step(&mut (), &Kin { u: 1.7, ..k }));
    let mut out = [0.0; 21];
    assert_eq!(m.write_params(&mut out), 21);
    assert_eq!(out, flat);
    assert!(Trig::from_params(&flat[..20], 1e-3).is_err());
    let bad = |blk: usize, v: [f32; 3]| {
        let mut f = flat;
        f[3 * blk..3 * blk + 3].copy_from_slice(&v);
        Trig::from_params(&f, 1e-3).is_err()
    };
    assert!(bad(0, [-0.1, 0.0, 0.0])); // D < 0
    assert!(bad(0, [0.1, -0.1, 0.0])); // D(2 A) < 0
    assert!(bad(1, [2.5, 0.0, 0.0])); // C > 2
    assert!(!bad(1, [0.5, 2.0, -1.0])); // C peaks at 1 A with 1.5: admissible
    assert!(bad(1, [1.0, 2.0, -0.5])); // C(2 A) = 3 > 2
    assert!(bad(2, [0.01, -0.01, 0.0])); // B(2 A) < 0
    assert!(bad(5, [-1.0, 0.0, 0.0])); // k < 0
    assert!(bad(6, [0.0, f32::NAN, 0.0]));
    assert!(!bad(3, [-50.0, 10.0, 3.0])); // S_h: any sign
    assert!(Trig::new(SEED002, 1e-3).is_ok());
}
