//! The firmware's configuration encoding round-trips with `hil-sim export`: both use
//! `model_core::control::page`, and what export writes is what the firmware's decoder
//! reads back, model parameters included.

use hil_sim::io::config_page;
use hil_sim::io::params_file::ParamsFile;
use model_core::control::config::WORDS;
use model_core::control::{ConfigImage, PageError, RateSpec};
use model_core::models::spencer::Spencer;
use model_core::Model;
use std::path::Path;

#[test]
fn export_round_trips_through_the_firmware_decoder() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../hil-sim/params/spencer_dyke_1997.json");
    let file = ParamsFile::read(&path).unwrap();
    let control = config_page::default_control(20_000.0).unwrap();
    let img = config_page::image(&file, &path, control).unwrap();
    let bytes = img.encode();
    let back = ConfigImage::decode(&bytes).unwrap();
    assert_eq!(back, img);
    assert_eq!(back.model_id(), "spencer");
    assert_eq!(back.params(), file.flat(&path).unwrap().as_slice());
    assert_eq!(back.control.get().dt, 1.0 / 20_000.0);
    let m: Spencer = back.model().unwrap();
    let mut p = vec![0.0; Spencer::N_PARAMS];
    m.write_params(&mut p);
    assert_eq!(p, back.params());
    // A flipped bit in the model parameters (after the 48-byte header and the control
    // words) is caught by the page CRC.
    let mut bad = bytes;
    bad[48 + 4 * WORDS + 4 * 3 + 1] ^= 4;
    assert!(matches!(ConfigImage::decode(&bad), Err(PageError::CrcMismatch { .. })));
}

#[test]
fn export_uses_the_files_rate_and_rejects_bad_sets() {
    let dir = std::env::temp_dir().join(format!("mrc-export-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("lugre.json");
    std::fs::write(
        &p,
        r#"{"model":"lugre","rate":"kalman:1e6:1e-6","params":{"alpha":4.312,"beta":5.771,"epsilon":0.003,"c":-0.151,"k":4.297,"t0":5.225}}"#,
    )
    .unwrap();
    let control = config_page::default_control(20_000.0).unwrap();
    let img = config_page::image(&ParamsFile::read(&p).unwrap(), &p, control).unwrap();
    assert_eq!(img.rate, RateSpec::Kalman { q: 1e6, r: 1e-6 });
    std::fs::write(&p, r#"{"model":"lugre","params":[-1,0,0,0,0,0]}"#).unwrap();
    let e = config_page::image(&ParamsFile::read(&p).unwrap(), &p, control).unwrap_err();
    assert!(format!("{e:#}").contains("alpha"), "{e:#}");
    std::fs::remove_dir_all(&dir).ok();
}
