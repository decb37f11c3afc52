#![allow(clippy::unwrap_used)]
use super::*;

/// Seed 003 eq. 13–14 at I = 0.5 A by hand, and the sgn(ẋ) jump.
#[test]
fn matches_seed003_polynomials() {
    let (fc, c0, f0) = SEED003;
    let m = Bingham::new(fc, c0, f0, 1e-3).unwrap();
    let i = 0.5f32;
    let fc_want = -910.09 * i * i * i + 986.49 * i * i + 663.56 * i + 52.19;
    let c0_want = 48.74 * i.powi(4) - 106.39 * i.powi(3) + 66.00 * i * i + 1.43 * i + 0.53;
    let v = 20.0; // mm/s
    let y = m.step(&mut (), &Kin::new(1.0, v, 0.0, i));
    assert!((y - (fc_want + c0_want * v + 40.0)).abs() < 1e-2, "{y}");
    let y = m.step(&mut (), &Kin::new(1.0, -v, 0.0, i));
    assert!((y - (-fc_want - c0_want * v + 40.0)).abs() < 1e-2, "{y}");
    // sgn(0) = 0: only the offset at rest.
    assert_eq!(m.step(&mut (), &Kin::new(1.0, 0.0, 0.0, i)), 40.0);
}

/// The linear-in-command form is the polynomial with higher coefficients zero.
#[test]
fn linear_form_and_validation() {
    let m = Bingham::from_params(&[100.0, 50.0, 0.0, 0.0, 2.0, 0.5, 0.0, 0.0, 0.0, -3.0], 1e-3).unwrap();
    let y = m.step(&mut (), &Kin::new(0.0, -4.0, 0.0, 2.0));
    assert!((y - (-(100.0 + 50.0 * 2.0) + (2.0 + 0.5 * 2.0) * -4.0 - 3.0)).abs() < 1e-4);
    let mut v = [0.0; 10];
    assert_eq!(m.write_params(&mut v), 10);
    assert_eq!(Bingham::from_params(&v, 1e-3).unwrap(), m);
    assert!(Bingham::from_params(&v[..9], 1e-3).is_err());
    assert!(Bingham::new([-1.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0, 0.0], 0.0, 1e-3).is_err());
    assert!(Bingham::new([1.0, f32::NAN, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0, 0.0], 0.0, 1e-3).is_err());
    assert!(Bingham::new([1.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0, 0.0], 0.0, -1.0).is_err());
}
