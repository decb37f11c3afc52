#![allow(clippy::unwrap_used)]
use super::*;
use crate::models::arctan::Arctan;

fn example() -> Params {
    Params { f0: [20.0, 5.0], cb: [900.0, 400.0], fy: [150.0, 700.0], k: [60.0, 10.0], xd0: [0.01, 0.005] }
}

/// m = 0 is eq. 16 exactly; otherwise the difference is m·ẍ.
#[test]
fn reduces_to_arctan_and_adds_inertia() {
    let base = Arctan::new(example(), 1e-3).unwrap();
    let zero = ArctanInertia::new(example(), 0.0, 1e-3).unwrap();
    let heavy = ArctanInertia::new(example(), 2.5, 1e-3).unwrap();
    for (v, a, u) in [(0.05f32, 3.0f32, 0.0f32), (-0.1, -40.0, 1.0), (0.0, 7.0, 2.0), (0.02, 0.0, 0.5)] {
        let k = Kin::new(0.01, v, a, u);
        let b = base.step(&mut (), &k);
        assert_eq!(zero.step(&mut (), &k), b);
        assert!((heavy.step(&mut (), &k) - (b + 2.5 * a)).abs() < 1e-3);
    }
    let mut p = [0.0; 11];
    assert_eq!(heavy.write_params(&mut p), 11);
    assert_eq!(p[10], 2.5);
    assert_eq!(ArctanInertia::from_params(&p, 1e-3).unwrap(), heavy);
    assert!(ArctanInertia::from_params(&p[..10], 1e-3).is_err());
    assert!(ArctanInertia::new(example(), f32::INFINITY, 1e-3).is_err());
}
