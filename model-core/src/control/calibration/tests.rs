use super::*;

fn cal() -> Calibration {
    Calibration { samples: 4, max_spread: 6, nominal_hall: 2048.0, nominal_current: 2048.0, max_offset_error: 100.0 }
}

#[test]
fn averages_offsets() {
    let c = cal();
    let mut s = CalibState::default();
    for h in [2060u16, 2062, 2058] {
        assert_eq!(c.step(&mut s, h, 2050), CalibResult::Pending);
    }
    assert_eq!(c.step(&mut s, 2060, 2046), CalibResult::Done { hall_offset: 2060.0, current_offset: 2049.0 });
    assert!((counts_to_units(2160, 2060.0, 0.001) - 0.1).abs() < 1e-6);
}

#[test]
fn rejects_noise_and_rails() {
    let c = cal();
    let mut s = CalibState::default();
    for h in [2048u16, 2070, 2048] {
        c.step(&mut s, h, 2048);
    }
    assert_eq!(c.step(&mut s, 2048, 2048), CalibResult::Failed);
    let results: Vec<_> = (0..4).map(|_| c.step(&mut s, 4095, 2048)).collect();
    assert_eq!(results.last(), Some(&CalibResult::Failed), "a rail reading must not calibrate");
}
