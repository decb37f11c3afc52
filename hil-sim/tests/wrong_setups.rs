//! Issue 18, defect 8 (part): set-ups that cannot be right are refused with the reason:
//! an export for a model the firmware is not built with, absurd parameter values, and the
//! same channel as input and output.

use std::path::Path;

mod common;
use common::{hil_sim, scratch, simulate_noise};

fn one_error(err: &str) -> bool {
    err.lines().filter(|l| l.starts_with("error")).count() == 1
}

fn bouc_wen(alpha: f32) -> String {
    let mut p = model_core::models::bouc_wen::SEED000_AVERAGE;
    p[0] = alpha;
    format!("{{\"model\":\"bouc_wen\",\"params\":{}}}", serde_json::to_string(&p.to_vec()).unwrap())
}

#[test]
fn export_refuses_what_the_firmware_cannot_run() {
    let dir = scratch("export");
    let out = dir.join("page.bin");
    let out = out.to_str().unwrap();
    // A model the firmware is not built with (`firmware::runner` lists the ones it runs).
    let spencer = Path::new(env!("CARGO_MANIFEST_DIR")).join("params/spencer_dyke_1997.json");
    let (code, _, err) = hil_sim(&["export", spencer.to_str().unwrap(), "--out", out]);
    assert_ne!(code, 0);
    assert!(err.contains("`spencer`") && err.contains("firmware runs only") && one_error(&err), "{err}");
    assert!(!Path::new(out).exists(), "a page was written");
    // α = 1e38: validated, but the output overflows f32 on a representative sweep.
    let p = dir.join("bw.json");
    std::fs::write(&p, bouc_wen(1e38)).unwrap();
    let (code, _, err) = hil_sim(&["export", p.to_str().unwrap(), "--out", out]);
    assert_ne!(code, 0);
    assert!(err.contains("bw.json") && err.contains("bouc_wen") && one_error(&err), "{err}");
    assert!(!Path::new(out).exists(), "a page was written");
    // The published set exports.
    std::fs::write(&p, bouc_wen(model_core::models::bouc_wen::SEED000_AVERAGE[0])).unwrap();
    let (code, _, err) = hil_sim(&["export", p.to_str().unwrap(), "--out", out]);
    assert_eq!(code, 0, "{err}");
    assert!(Path::new(out).exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_output_cannot_be_the_input() {
    let dir = scratch("channels");
    let rec = dir.join("rec.csv");
    simulate_noise(&rec);
    let rec = rec.to_str().unwrap();
    for args in [
        vec!["fit", rec, "--model", "algebraic", "--input", "torque", "--output", "torque"],
        vec!["fit", rec, "--model", "algebraic", "--output", "t"],
        vec!["diagnose", rec, "--model", "algebraic", "--input", "torque"],
    ] {
        let (code, out, err) = hil_sim(&args);
        assert_ne!(code, 0, "{args:?}: {out}");
        assert!(err.contains("must be different channels") && one_error(&err), "{args:?}: {err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 17: `export` writes the page at the rate the firmware runs the model at
/// (`firmware::runner::control_hz_of`), says it, and refuses another rate with the reason.
#[test]
fn export_writes_and_prints_the_models_control_rate() {
    let dir = scratch("export-rate");
    let out = dir.join("page.bin");
    let p = dir.join("gpi.json");
    std::fs::write(&p, r#"{"model":"gpi","params":[1.0,0.1,1.0,1.0,1.0,0.5,0.2,1.0,0.5,0.2,-1.0,1.0,0.0]}"#).unwrap();
    let want = firmware::runner::control_hz_of("gpi").expect("gpi runs on the board");
    assert_eq!(want, 10_000, "gpi's step and slow pass overrun a 20 kHz period");
    let (code, text, err) = hil_sim(&["export", p.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(text.contains("runs it at 10000 Hz"), "{text}");
    let page = model_core::control::ConfigImage::decode(&std::fs::read(&out).unwrap()).expect("page");
    assert_eq!(page.control.get().dt, 1.0 / 10_000.0);
    let (code, _, err) =
        hil_sim(&["export", p.to_str().unwrap(), "--out", out.to_str().unwrap(), "--control-hz", "20000"]);
    assert_ne!(code, 0);
    assert!(err.contains("runs at 10000 Hz") && one_error(&err), "{err}");
    // Preisach runs on the board (built in place in a static slot), at its rate. The output
    // scale 0.05 keeps its estimate within the clutch's rating (at scale 1 the 1275 relays'
    // density values sum to 300 N·m, which the physics check refuses).
    let p = dir.join("preisach.json");
    std::fs::write(&p, r#"{"model":"preisach","params":[1.0,2.0,0.1,0.05,0.1,0.05,-1.0,1.0,0.0]}"#).unwrap();
    let (code, text, err) = hil_sim(&["export", p.to_str().unwrap(), "--out", out.to_str().unwrap(), "--json"]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&text).expect("json");
    assert_eq!((v["model"].as_str(), v["control_hz"].as_f64()), (Some("preisach"), Some(10_000.0)), "{v}");
    let page = model_core::control::ConfigImage::decode(&std::fs::read(&out).unwrap()).expect("page");
    assert!(firmware::runner::Loop::from_image(&page).is_ok_and(|l| l.control_hz() == 10_000));
    let _ = std::fs::remove_dir_all(&dir);
}
