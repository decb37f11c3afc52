use super::*;

#[test]
fn integrates_and_stops_at_the_limit() {
    let pi = Pi::new(1.0, 100.0, 0.01, -2.0, 2.0);
    let mut s = PiState::default();
    let u1 = pi.step(&mut s, 1.0, 0.0);
    assert!((u1 - 1.0).abs() < 1e-6 && (s.integral - 1.0).abs() < 1e-6);
    for _ in 0..100 {
        assert!(pi.step(&mut s, 1.0, 0.0) <= 2.0);
    }
    let wound = s.integral;
    assert!(wound <= 2.0, "integral {wound}");
    // Anti-windup: a sign change of the error leaves saturation at once.
    let u = pi.step(&mut s, -1.0, 0.0);
    assert!(u < 2.0, "{u}");
}

#[test]
fn nan_is_harmless() {
    let pi = Pi::new(1.0, 1.0, 0.01, -1.0, 1.0);
    let mut s = PiState::default();
    assert_eq!(pi.step(&mut s, f32::NAN, f32::NAN), 0.0);
    assert_eq!(s, PiState::default());
    assert_eq!(clamp(f32::NAN, -1.0, 1.0), -1.0);
}
