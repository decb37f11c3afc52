#![allow(clippy::unwrap_used)]
use super::*;

fn example() -> Params {
    // Units of seed 001 (N, m/s); values only plausible (the paper publishes a plot).
    Params { f0: [20.0, 5.0], cb: [900.0, 400.0], fy: [150.0, 700.0], k: [60.0, 10.0], xd0: [0.01, 0.005] }
}

/// Eq. 16 by hand on both branches of sgn(ẍ), command 1.2.
#[test]
fn matches_eq16() {
    let m = Arctan::new(example(), 1e-3).unwrap();
    let u = 1.2f32;
    let (f0, cb, fy, k, x0) = (20.0 + 5.0 * u, 900.0 + 400.0 * u, 150.0 + 700.0 * u, 60.0 + 10.0 * u, 0.01 + 0.005 * u);
    for (v, a) in [(0.05f32, 3.0f32), (0.05, -3.0), (-0.02, 1.0), (0.0, 0.0)] {
        let sg = if a > 0.0 {
            1.0
        } else if a < 0.0 {
            -1.0
        } else {
            0.0
        };
        let want = f0 + cb * v + 2.0 / core::f32::consts::PI * fy * (k * (v - x0 * sg)).atan();
        let y = m.step(&mut (), &Kin::new(0.0, v, a, u));
        assert!((y - want).abs() < 1e-3, "v {v} a {a}: {y} vs {want}");
    }
    // The hysteresis: same velocity, opposite acceleration, different force.
    let up = m.step(&mut (), &Kin::new(0.0, 0.0, 1.0, u));
    let down = m.step(&mut (), &Kin::new(0.0, 0.0, -1.0, u));
    assert!(down > up);
}

#[test]
fn validation_and_round_trip() {
    let m = Arctan::new(example(), 1e-3).unwrap();
    let mut v = [0.0; 10];
    assert_eq!(m.write_params(&mut v), 10);
    assert_eq!(Arctan::from_params(&v, 1e-3).unwrap(), m);
    assert!(Arctan::from_params(&v[..9], 1e-3).is_err());
    assert!(Arctan::new(Params { fy: [-1.0, 0.0], ..example() }, 1e-3).is_err());
    assert!(Arctan::new(Params { k: [1.0, f32::NAN], ..example() }, 1e-3).is_err());
}
