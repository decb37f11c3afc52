//! Driving `hil-sim` as a user drives it against a board: the binary of the test's
//! profile, a virtual board in its own process, scratch folders, the journal and the
//! recordings read back. Shared by the board-link tests and the fault-injection suite.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use serde_json::Value;

pub fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../target"))
}

/// The `hil-sim` binary of this test's profile, built if needed; `MRC_HIL_SIM` names
/// another build to drive instead (to run the same cases against an older `hil-sim`).
pub fn hil_sim() -> PathBuf {
    if let Some(p) = std::env::var_os("MRC_HIL_SIM") {
        return PathBuf::from(p);
    }
    let release = !cfg!(debug_assertions);
    let mut cmd = Command::new(option_env!("CARGO").unwrap_or("cargo"));
    cmd.args(["build", "-q", "-p", "hil-sim", "--bin", "hil-sim"]);
    if release {
        cmd.arg("--release");
    }
    let st = cmd.status().expect("running cargo build -p hil-sim");
    assert!(st.success(), "cargo build -p hil-sim failed");
    target_dir().join(if release { "release" } else { "debug" }).join("hil-sim")
}

pub fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("mrc-board-link-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("scratch dir");
    d
}

pub fn run(bin: &Path, dir: &Path, args: &[&str]) -> String {
    let out = Command::new(bin).current_dir(dir).args(args).output().expect("running hil-sim");
    assert!(out.status.success(), "hil-sim {args:?}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).expect("utf-8")
}

/// Run `hil-sim` expecting it to fail: its stderr.
pub fn fail(bin: &Path, dir: &Path, args: &[&str]) -> String {
    let out = Command::new(bin).current_dir(dir).args(args).output().expect("running hil-sim");
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "hil-sim {args:?} exited 0: {}{err}", String::from_utf8_lossy(&out.stdout));
    err
}

/// Whether the journal holds `event value` (any value when `value` is empty).
pub fn journal_has(path: &Path, event: &str, value: &str) -> bool {
    path.exists() && journal(path).iter().any(|e| e.1 == event && (value.is_empty() || e.2 == value))
}

pub fn json(bin: &Path, dir: &Path, args: &[&str]) -> Value {
    let text = run(bin, dir, args);
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("hil-sim {args:?}: not JSON ({e}): {text}"))
}

/// A running virtual board, killed on drop.
pub struct Board {
    pub child: Child,
    pub port: String,
    /// Its stderr after `ready`, line by line.
    pub log: std::sync::mpsc::Receiver<String>,
}

impl Drop for Board {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

pub fn virtual_board(bin: &Path, dir: &Path, extra: &[&str]) -> Board {
    let mut child = Command::new(bin)
        .current_dir(dir)
        .args(["virtual-board", "--listen", "tcp:127.0.0.1:0"])
        .args(extra)
        .stderr(Stdio::piped())
        .stdout(Stdio::null())
        .spawn()
        .expect("starting the virtual board");
    let mut lines = BufReader::new(child.stderr.take().expect("stderr")).lines();
    let mut port = None;
    for line in lines.by_ref() {
        let line = line.expect("stderr line");
        if let Some(at) = line.find("tcp:") {
            port = Some(line[at..].trim().to_owned());
        }
        if line.trim() == "ready" {
            break;
        }
    }
    let port = port.expect("the virtual board printed its address before `ready`");
    // Keep draining stderr so the board never blocks on a full pipe.
    let (tx, log) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for l in lines.map_while(Result::ok) {
            let _ = tx.send(l);
        }
    });
    Board { child, port, log }
}

/// One row of a recording: the header's columns by name.
pub fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).expect("recording");
    let mut it = text.lines();
    let head = it.next().expect("header").split(',').map(str::to_owned).collect();
    (head, it.map(|l| l.split(',').map(str::to_owned).collect()).collect())
}

pub fn col(head: &[String], name: &str) -> usize {
    head.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column `{name}` in {head:?}"))
}

/// The journal: (sample, event, value).
pub fn journal(path: &Path) -> Vec<(usize, String, String)> {
    std::fs::read_to_string(path)
        .expect("journal")
        .lines()
        .map(|l| {
            let mut w = l.split_whitespace();
            let k = w.next().and_then(|k| k.parse().ok()).expect("sample index");
            (k, w.next().unwrap_or("").to_owned(), w.next().unwrap_or("").to_owned())
        })
        .collect()
}
