//! Every file in `tests/corpus/` that is not a good recording makes the real binary fail
//! the contract's way: non-zero exit, nothing on stdout, exactly one line on stderr naming
//! the file (and the line or sample where there is one) and the reason, and no panic.

use std::path::{Path, PathBuf};
use std::process::Command;

fn corpus(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus").join(name)
}

/// A parameter file of its own for each caller (the tests run in parallel: one shared file
/// could be read while another test rewrites it).
fn params() -> PathBuf {
    static N: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!("hil-sim-broken-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(format!("p{}.json", N.fetch_add(1, std::sync::atomic::Ordering::SeqCst)));
    std::fs::write(&p, r#"{"model":"algebraic","params":{"k":1,"c":0,"alpha":0,"t0":0}}"#).unwrap();
    p
}

/// (file, what stderr must contain besides the file name)
const BROKEN: &[(&str, &[&str])] = &[
    ("missing_column.csv", &["no column `torque`", "t, b"]),
    ("text_in_number.csv", &["text_in_number.csv:4:", "`0.2x` is not a number"]),
    ("nan.csv", &["nan.csv:4:", "NaN"]),
    ("time_not_increasing.csv", &["time_not_increasing.csv:5:", "does not increase"]),
    ("empty.csv", &["the file is empty"]),
    ("header_only.csv", &["no data rows"]),
    ("ragged_row.csv", &["ragged_row.csv:4:", "4 fields but the header names 3"]),
    ("short_row.csv", &["short_row.csv:3:", "column `torque` has no value"]),
    ("truncated.mat", &["truncated MAT-file", "runs past the end"]),
    ("matrix_shape.mat", &["variable `torque` is a 3×4 matrix"]),
    ("length_mismatch.mat", &["variable `torque` has 40 samples but `t` has 50"]),
    ("nan.mat", &["variable `torque`, sample 17", "NaN"]),
    ("time_not_increasing.mat", &["sample 31: time", "does not increase"]),
    ("garbage.bin", &["binary data"]),
];

#[test]
fn broken_recordings_fail_with_one_line_naming_file_and_reason() {
    let p = params();
    for (name, needles) in BROKEN {
        let file = corpus(name);
        assert!(file.is_file(), "missing corpus file {name}");
        let out = Command::new(env!("CARGO_BIN_EXE_hil-sim"))
            .args(["replay", file.to_str().unwrap(), "--params", p.to_str().unwrap(), "--json"])
            .output()
            .unwrap();
        let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
        assert!(!out.status.success(), "{name}: exit 0");
        assert!(stdout.is_empty(), "{name}: stdout {stdout}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{name}: {stderr}");
        assert!(!stderr.contains("panicked"), "{name}: {stderr}");
        assert!(stderr.starts_with("error: "), "{name}: {stderr}");
        assert!(stderr.contains(name), "{name}: {stderr}");
        for n in *needles {
            assert!(stderr.contains(n), "{name}: no `{n}` in {stderr}");
        }
    }
}

#[test]
fn good_mat_files_replay_like_csv() {
    let p = params();
    for name in ["good.mat", "good_compressed.mat"] {
        let out = Command::new(env!("CARGO_BIN_EXE_hil-sim"))
            .args(["replay", corpus(name).to_str().unwrap(), "--params", p.to_str().unwrap(), "--json"])
            .output()
            .unwrap();
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["samples"], 50);
        assert_eq!(v["warnings"], serde_json::json!([]));
    }
}

/// A variable no command uses is skipped, however unreadable as a channel: the file replays,
/// and `--verbose` says what was skipped and why.
#[test]
fn unused_variables_are_skipped_and_listed() {
    let p = params();
    let file = corpus("char_variable.mat");
    let out = Command::new(env!("CARGO_BIN_EXE_hil-sim"))
        .args(["replay", file.to_str().unwrap(), "--params", p.to_str().unwrap(), "--json", "--verbose"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("skipped variable `notes` is a char array"), "{stderr}");
}
