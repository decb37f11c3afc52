#![allow(clippy::unwrap_used)]
use super::*;

#[test]
fn crc_is_the_ieee_crc32() {
    // The check value of CRC-32/ISO-HDLC: "123456789" → 0xCBF43926.
    assert_eq!(!crc32_update(!0, b"123456789"), 0xCBF4_3926);
}

#[test]
fn bytes_round_trip_and_detect_corruption() {
    let v = ControlConfig::defaults(1e-4).validate().unwrap();
    let bytes = v.to_bytes();
    assert_eq!(ValidatedConfig::from_bytes(&bytes).unwrap(), v);
    for bit in [0usize, 77, 8 * BYTES - 1] {
        let mut b = bytes;
        if let Some(x) = b.get_mut(bit / 8) {
            *x ^= 1 << (bit % 8);
        }
        assert!(matches!(ValidatedConfig::from_bytes(&b), Err(ConfigError::CrcMismatch { .. })), "bit {bit}");
    }
}

#[test]
fn validation_rejects_bad_values() {
    let d = ControlConfig::defaults(1e-4);
    assert!(ControlConfig { dt: 0.0, ..d }.validate().is_err());
    assert!(ControlConfig { kp_i: f32::NAN, ..d }.validate().is_err());
    assert!(ControlConfig { over_current: 1.0, ..d }.validate().is_err()); // below i_max
    assert!(ControlConfig { calib_samples: 2.5, ..d }.validate().is_err());
    assert!(ControlConfig { hall_rail_hi: 10.0, ..d }.validate().is_err());
}

#[test]
fn verify_finds_any_flipped_bit() {
    let v = ControlConfig::defaults(1e-4).validate().unwrap();
    assert!(v.verify());
    for bit in [0u32, 31, 500, 1407] {
        let mut bad = v;
        bad.inject_bit_flip(bit);
        assert_ne!(bad.get().to_words().map(f32::to_bits), v.get().to_words().map(f32::to_bits), "bit {bit}");
        assert!(!bad.verify(), "bit {bit}");
    }
    // A stray write to a coefficient (not to the settings) is caught too.
    let mut bad = v;
    bad.k.ki_i_dt = f32::from_bits(bad.k.ki_i_dt.to_bits() ^ 1);
    assert!(!bad.verify());
}
