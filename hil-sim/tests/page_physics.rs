//! A parameter set that would drive the clutch wrongly is refused before a page is written
//! (`export`) or sent (`board load`), by the board's own physics check of the page: the
//! estimate on a slow field sweep must be finite, within the rating and rising with the
//! field; and the set must have been fitted from a field to a torque.

use std::io::Read;
use std::net::TcpListener;
use std::path::{Path, PathBuf};

use hil_sim::io::config_page;
use hil_sim::io::page_physics::{self, PagePhysicsError};
use hil_sim::io::params_file::ParamsFile;
use model_core::control::PhysicsFault;

mod common;
use common::{hil_sim, scratch};

fn one_error(err: &str) -> bool {
    err.lines().filter(|l| l.starts_with("error")).count() == 1
}

/// The host's check of the page `export` would write for `path`.
fn checked(path: &Path) -> Result<(), PagePhysicsError> {
    let file = ParamsFile::read(path).unwrap();
    let (_, control) = config_page::firmware_control(&file.model, None).unwrap();
    let img = config_page::firmware_image(&file, path, control).unwrap();
    page_physics::check(&file, path, &img)
}

/// `export PARAMS --out page.bin` in `dir`: exit code, stderr, whether the page exists.
fn export(dir: &Path, params: &Path) -> (i32, String, bool) {
    let out = dir.join("page.bin");
    let _ = std::fs::remove_file(&out);
    let (code, _, err) = hil_sim(&["export", params.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    (code, err, out.exists())
}

/// `simulate --scenario sine_1hz` + `fit --model algebraic --save`: the set README's bench
/// loads on the virtual board.
fn fitted_algebraic(dir: &Path) -> PathBuf {
    let sim = dir.join("sim.csv");
    let (code, _, err) = hil_sim(&["simulate", "--scenario", "sine_1hz", "--out", sim.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let save = dir.join("fitted");
    let (code, _, err) =
        hil_sim(&["fit", sim.to_str().unwrap(), "--model", "algebraic", "--save", save.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    save.join("algebraic.json")
}

/// `file` with its JSON changed by `edit`, written to `dir/name`.
fn edited(dir: &Path, file: &Path, name: &str, edit: impl FnOnce(&mut serde_json::Value)) -> PathBuf {
    let mut v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(file).unwrap()).unwrap();
    edit(&mut v);
    let p = dir.join(name);
    std::fs::write(&p, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    p
}

#[test]
fn a_fitted_clutch_set_exports_and_with_its_stiffness_flipped_is_refused() {
    let dir = scratch("physics-flipped");
    let good = fitted_algebraic(&dir);
    assert!(checked(&good).is_ok(), "{:?}", checked(&good));
    let (code, err, written) = export(&dir, &good);
    assert!(code == 0 && written, "{err}");

    let flipped = edited(&dir, &good, "flipped.json", |v| {
        let k = v["params"]["k"].as_f64().unwrap();
        v["params"]["k"] = (-k).into();
    });
    match checked(&flipped) {
        Err(PagePhysicsError::Physics {
            fault: PhysicsFault::Decreasing { high, low, .. }, channels: None, ..
        }) => {
            assert!(high.b < 0.01 && high.torque > 0.0 && low.b > 0.7 && low.torque < -20.0, "{high:?} {low:?}");
        }
        other => panic!("{other:?}"),
    }
    let (code, err, written) = export(&dir, &flipped);
    assert_ne!(code, 0);
    assert!(!written, "a refused page was written");
    assert!(
        one_error(&err)
            && err.contains("flipped.json: refused: the estimate decreases as the field rises")
            && err.contains("N·m at 0.00 T")
            && err.contains("stiffness has the wrong sign"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn board_load_refuses_before_sending_anything() {
    let dir = scratch("physics-load");
    let seed = dir.join("seed.json");
    let [k, c, alpha, t0] = model_core::models::algebraic::SEED000_AVERAGE;
    let flat = serde_json::json!({ "model": "algebraic", "params": [-k, c, alpha, t0] });
    std::fs::write(&seed, flat.to_string()).unwrap();
    // A board that reads whatever comes and never answers.
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let port = format!("tcp:{}", listener.local_addr().unwrap());
    let board = std::thread::spawn(move || {
        let (mut s, _) = listener.accept().unwrap();
        let mut got = Vec::new();
        let _ = s.read_to_end(&mut got);
        got.len()
    });
    let (code, _, err) = hil_sim(&["board", "--port", &port, "load", seed.to_str().unwrap()]);
    assert_ne!(code, 0);
    assert!(one_error(&err) && err.contains("seed.json: refused: the estimate decreases as the field rises"), "{err}");
    assert_eq!(board.join().unwrap(), 0, "bytes were sent to the board");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_damper_set_is_refused_as_beyond_the_rating_naming_its_channels() {
    let dir = scratch("physics-damper");
    let dyke = hil_sim::io::bundled::data_file("dyke/ranran_50.csv").unwrap();
    let save = dir.join("dahl");
    let (code, _, err) = hil_sim(&[
        "fit",
        dyke.to_str().unwrap(),
        "--input",
        "D",
        "--output",
        "F",
        "--model",
        "dahl",
        "--save",
        save.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let dahl = save.join("dahl.json");
    match checked(&dahl) {
        Err(PagePhysicsError::Physics { fault: PhysicsFault::ExceedsRating { at, limit }, channels, .. }) => {
            // Its Dahl variable saturates within a few hundredths of a tesla: hundreds of
            // "N·m" (its newtons) against a 30 N·m limit.
            assert!(at.torque.abs() > 300.0 && limit == 30.0, "{at:?}");
            assert_eq!(channels, Some(("D".to_owned(), "F".to_owned())));
        }
        other => panic!("{other:?}"),
    }
    let (code, err, written) = export(&dir, &dahl);
    assert!(code != 0 && !written, "{err}");
    assert!(
        one_error(&err)
            && err.contains("dahl.json: refused: the estimate reaches")
            && err.contains("beyond 30.0 N·m")
            && err.contains("fitted on `D` → `F` (cm → N)"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_physical_set_fitted_on_other_channels_is_refused_naming_both() {
    let dir = scratch("physics-channels");
    let good = fitted_algebraic(&dir);
    let renamed = edited(&dir, &good, "renamed.json", |v| {
        v["channels"]["input"] = "D".into();
        v["channels"]["output"] = "F".into();
    });
    assert!(matches!(checked(&renamed), Err(PagePhysicsError::Channels { .. })), "{:?}", checked(&renamed));
    let (code, err, written) = export(&dir, &renamed);
    assert!(code != 0 && !written, "{err}");
    assert!(
        one_error(&err) && err.contains("renamed.json: refused: the set was fitted on `D` → `F` (cm → N)"),
        "{err}"
    );
    // The board's own estimate is a torque channel (`board record` writes `torque_est`).
    let bench = edited(&dir, &good, "bench.json", |v| v["channels"]["output"] = "torque_est".into());
    assert!(checked(&bench).is_ok(), "{:?}", checked(&bench));
    // A published set says nothing of its channels: the physics check alone judges it.
    let seed = dir.join("seed.json");
    let p = model_core::models::algebraic::SEED000_AVERAGE;
    std::fs::write(&seed, serde_json::json!({ "model": "algebraic", "params": p }).to_string()).unwrap();
    let (code, err, written) = export(&dir, &seed);
    assert!(code == 0 && written, "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
