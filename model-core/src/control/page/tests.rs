#![allow(clippy::unwrap_used, clippy::indexing_slicing)]
use super::*;
use crate::models::bouc_wen::BoucWen;

fn image() -> ConfigImage {
    let dt = 5e-5;
    let control = ControlConfig { kp_t: 0.2, ..ControlConfig::defaults(dt) }.validate().unwrap();
    let p = crate::models::bouc_wen::SEED000_AVERAGE;
    ConfigImage::new("bouc_wen", &p, RateSpec::Kalman { q: 1e6, r: 1e-6 }, control).unwrap()
}

#[test]
fn round_trip_and_model() {
    let img = image();
    let bytes = img.encode();
    assert_eq!(&bytes[..4], b"MRCC");
    let back = ConfigImage::decode(&bytes).unwrap();
    assert_eq!(back, img);
    assert_eq!(back.model_id(), "bouc_wen");
    let m: BoucWen = back.model().unwrap();
    assert_eq!(m.dt(), 5e-5);
    assert!(back.model::<crate::models::lugre::LuGre>().is_err());
    assert_eq!(bytes[PAGE_BYTES - 1], 0xFF);
}

#[test]
fn the_crc_covers_every_byte_up_to_it() {
    let bytes = image().encode();
    let len = usize::from(u16::from_le_bytes([bytes[6], bytes[7]]));
    for at in [0usize, 5, 9, 33, 44, 48, 100, len - 4, len - 1] {
        let mut b = bytes;
        b[at] ^= 0x10;
        assert!(ConfigImage::decode(&b).is_err(), "flip at {at} accepted");
    }
    // Model parameters are covered (they were not by the control config's own CRC).
    let mut b = bytes;
    b[len - 2] ^= 1;
    assert!(matches!(ConfigImage::decode(&b), Err(PageError::CrcMismatch { .. })));
    assert_eq!(ConfigImage::decode(&[0xFF; PAGE_BYTES]), Err(PageError::BadMagic));
}

#[test]
fn limits() {
    let c = ControlConfig::defaults(1e-4).validate().unwrap();
    assert!(ConfigImage::new("", &[], RateSpec::Backward, c).is_err());
    assert!(ConfigImage::new("a_very_long_model_identifier", &[], RateSpec::Backward, c).is_err());
    assert!(ConfigImage::new("narx", &[0.0; MAX_PARAMS + 1], RateSpec::Backward, c).is_err());
    assert!(ConfigImage::new("x", &[f32::NAN], RateSpec::Backward, c).is_err());
    const { assert!(MAX_PARAMS >= 400) };
}
