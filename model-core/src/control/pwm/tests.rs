use super::*;

#[test]
fn duty_limits_and_quantises() {
    assert_eq!(duty(12.0, 24.0, 0.95, 1000.0), (0.5, 500));
    assert_eq!(duty(100.0, 24.0, 0.95, 1000.0), (0.95, 950));
    assert_eq!(duty(-0.01234, 1.0, 0.95, 1000.0), (-0.012, -12));
    assert_eq!(duty(1.0, 0.0, 0.95, 1000.0), (0.0, 0));
    assert_eq!(duty(f32::NAN, 24.0, 0.95, 1000.0), (0.0, 0));
}

#[test]
fn quantise_rounds_to_the_nearest_count() {
    assert_eq!(quantise(0.5, 1000.0), (0.5, 500));
    assert_eq!(quantise(0.95, 1000.0), (0.95, 950));
    assert_eq!(quantise(-0.95, 1000.0), (-0.95, -950));
    assert_eq!(quantise(-0.01234, 1000.0), (-0.012, -12));
    assert_eq!(quantise(0.0125, 1000.0).1, 13);
    assert_eq!(quantise(-0.0125, 1000.0).1, -12);
    assert_eq!(quantise(1.0, 65535.0).1, 65535);
    assert_eq!(quantise(-1.0, 65535.0).1, -65535);
    for k in -1300..=1300 {
        let d = k as f32 * 0.000_731;
        let (duty, c) = quantise(d, 4250.0);
        let exact = f64::from(d) * 4250.0;
        assert!((f64::from(c) - exact).abs() <= 0.51, "{d}: {c} for {exact}");
        assert!((duty - c as f32 / 4250.0).abs() == 0.0);
    }
}

#[test]
fn pulse_after_the_command_returns_to_zero() {
    let d = Demag { duty: 0.5, samples: 3, threshold: 1.0 };
    let mut s = DemagState::default();
    assert_eq!(d.step(&mut s, 0.0, 0.0), None, "not armed yet");
    assert_eq!(d.step(&mut s, 5.0, 2.0), None);
    assert_eq!(d.step(&mut s, 0.5, 1.0), None, "above a quarter of the threshold");
    let pulse: Vec<_> = (0..5).map(|_| d.step(&mut s, 0.0, 1.0)).collect();
    assert_eq!(pulse, vec![Some(-0.5), Some(-0.5), Some(-0.5), None, None]);
}
