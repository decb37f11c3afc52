//! The data-quality check on the two real Dyke recordings: it finds exactly the known
//! problems, where they are, and nothing else (run with `--release`; 134k rows).

use std::path::{Path, PathBuf};

use hil_sim::io::recording::Channels;
use hil_sim::io::recording::Recording;
use hil_sim::quality::{check, WarningKind};

fn dyke(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/dyke").join(name)
}

fn damper() -> Channels {
    Channels { time: "t".into(), input: "D".into(), output: "F".into(), command: Some("Y".into()), set: Vec::new() }
}

fn found(name: &str) -> Vec<(WarningKind, String, f64, f64)> {
    let rec = Recording::read(&dyke(name)).unwrap();
    let q = check(&rec, &damper()).unwrap();
    for w in &q.warnings {
        eprintln!("{}", w.message);
    }
    q.warnings.into_iter().map(|w| (w.kind, w.channel, w.start_s, w.end_s)).collect()
}

fn assert_same(found: &[(WarningKind, String, f64, f64)], expected: &[(WarningKind, &str, f64, f64)]) {
    assert_eq!(found.len(), expected.len(), "{found:?}");
    for (f, e) in found.iter().zip(expected) {
        let ok = f.0 == e.0 && f.1 == e.1 && (f.2 - e.2).abs() <= 0.05 && (f.3 - e.3).abs() <= 0.05;
        assert!(ok, "found {f:?}, expected {e:?}");
    }
}

/// ranran_50.csv: the excitation stops at 21.2 s; D then rests near −0.01 cm to the end.
#[test]
fn ranran_50_input_stands_still_from_21_2_s() {
    assert_same(&found("ranran_50.csv"), &[(WarningKind::Standstill, "D", 21.23, 24.65)]);
}

/// ransim_u.csv: from 19.53 s to 19.91 s the actuator sits at its stop (D ≈ 1.06–1.10 cm,
/// its maximum), and the force sensor twice reads its full-scale 4545.45 N flat.
#[test]
fn ransim_u_hits_the_end_stop_and_force_full_scale() {
    assert_same(
        &found("ransim_u.csv"),
        &[
            (WarningKind::Clipped, "D", 19.53, 19.91),
            (WarningKind::Clipped, "F", 19.59, 19.62),
            (WarningKind::Clipped, "F", 19.85, 19.89),
        ],
    );
}
