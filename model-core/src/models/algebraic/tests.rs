#![allow(clippy::unwrap_used, clippy::indexing_slicing)]
use super::*;

#[test]
fn matches_eq14() {
    let m = Algebraic::from_params(&SEED000_AVERAGE, 1e-3).unwrap();
    let y = m.step(&mut (), &Kin::new(1.5, 2.0, 0.0, 0.0));
    let want = 4.606 * 1.5 - 0.076 * 2.0 + 0.033 * 1.5 * 1.5f32.powi(3) + 0.797;
    assert!((y - want).abs() < 1e-5, "{y} vs {want}");
}

#[test]
fn rejects_non_finite() {
    assert!(Algebraic::new(f32::NAN, 0.0, 0.0, 0.0, 1e-3).is_err());
    assert!(Algebraic::new(1.0, 0.0, 0.0, 0.0, 0.0).is_err());
    assert!(Algebraic::from_params(&[1.0, 2.0], 1e-3).is_err());
}
