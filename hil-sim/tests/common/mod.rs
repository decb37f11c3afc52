//! What the command-line tests share: running the binary under a deadline, a fresh scratch
//! folder, and a short simulated recording.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Run `hil-sim ARGS`: exit code, stdout, stderr. Fails the test if it runs longer than
/// ten minutes (a hang, not a slow machine).
pub fn hil_sim(args: &[&str]) -> (i32, String, String) {
    hil_sim_within(args, 600)
}

/// [`hil_sim`] that fails the test after `deadline_s` seconds, killing the process.
pub fn hil_sim_within(args: &[&str], deadline_s: u64) -> (i32, String, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_hil-sim"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(deadline_s) {
            child.kill().unwrap();
            panic!("hil-sim {args:?} still running after {deadline_s} s");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = child.wait_with_output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A fresh, empty scratch folder for one test.
pub fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hil-sim-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A short simulated clutch recording at `path` (4 s at 500 Hz, algebraic truth, band-limited
/// noise, a concealed field lag).
pub fn simulate_noise(path: &Path) {
    simulate_noise_with(path, 1, 4.0, 500.0);
}

/// [`simulate_noise`] with its random seed, duration (s) and sampling rate (Hz).
pub fn simulate_noise_with(path: &Path, seed: u64, duration_s: f64, fs: f64) {
    let (seed, duration, fs) = (seed.to_string(), duration_s.to_string(), fs.to_string());
    let (code, _, err) = hil_sim(&[
        "simulate",
        "--effect",
        "field_lag",
        "--base",
        "algebraic",
        "--excitation",
        "noise",
        "--seed",
        &seed,
        "--duration",
        &duration,
        "--fs",
        &fs,
        "--out",
        path.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
}
