//! Issue 17 acceptance: `hil-sim virtual-board` (the firmware's application on the host)
//! driven through `hil-sim board --port tcp:…` as a user drives a board: a set fitted by
//! `fit --save` on a simulated recording is loaded (page CRC as `export` prints it), the
//! bridge enabled, 3 s recorded while a multi-sine torque profile plays, and the recording
//! fitted as it is. `hil-sim loop --replay` then runs the board's journal of what it
//! applied when through the bench `loop` runs (`closed_loop::rig` with the firmware's
//! controller built from the same page by the same configuration store): every recorded
//! torque estimate and true torque must be the same f32, bit for bit. A second board with `--fault hall_open@1.0` must latch the fault within
//! 2 ms of simulated time and report it in `board status`.
//!
//! Runs the `hil-sim` binary (built by this test with `cargo build -p hil-sim` in the test's
//! own profile if needed); the virtual board runs in simulated real time (~10 s in all).

use std::path::Path;
use std::process::Command;

use integration_tests::board::{col, hil_sim, journal, json, read_csv, run, scratch, virtual_board};

fn multisine_profile(path: &Path) {
    let mut text = String::from("t,reference\n");
    for k in 0..=3000 {
        let t = f64::from(k) * 1e-3;
        let w = 2.0 * std::f64::consts::PI * t;
        let r = 6.0 + 2.0 * (1.3 * w).sin() + 1.5 * (3.7 * w + 1.0).sin() + 1.0 * (7.1 * w + 2.0).sin();
        text += &format!("{t:.3},{r:.4}\n");
    }
    std::fs::write(path, text).expect("profile");
}

#[test]
fn load_enable_record_fit_and_the_same_numbers_as_loop() {
    record_fit_and_replay("algebraic", 20_000.0);
}

/// A model the board runs at 10 kHz: the board boots at 20 kHz and changes its step at the
/// swap; `loop --replay` follows it sample for sample.
#[test]
fn a_page_at_its_own_control_rate_gives_the_same_numbers_as_loop() {
    record_fit_and_replay("gpi", 10_000.0);
}

/// Fit `model` on a simulated run, load it on a virtual board, record 3 s driven by a
/// multisine, fit the recording, and replay the board's journal with `loop`: every recorded
/// sample equals the loop's sample at the same time, to the bit. `hz` is the page's rate.
fn record_fit_and_replay(model: &str, hz: f64) {
    let bin = hil_sim();
    let dir = scratch(&format!("record-{model}"));
    let fitted = format!("fitted/{model}.json");
    run(&bin, &dir, &["simulate", "--scenario", "sine_1hz", "--out", "sim.csv"]);
    run(&bin, &dir, &["fit", "sim.csv", "--model", model, "--save", "fitted", "--json"]);
    let exported = json(&bin, &dir, &["export", &fitted, "--out", "page.bin", "--json"]);
    multisine_profile(&dir.join("profile.csv"));

    let board = virtual_board(&bin, &dir, &["--journal", "journal.txt"]);
    let p = board.port.as_str();
    let loaded = json(&bin, &dir, &["board", "--port", p, "--json", "load", &fitted]);
    assert_eq!(loaded["ok"], true, "{loaded}");
    assert_eq!(loaded["crc"], exported["crc"], "the board verified another page than `export` writes");
    assert!(loaded["bytes"].as_u64().is_some_and(|b| b > 0), "{loaded}");
    assert_eq!(json(&bin, &dir, &["board", "--port", p, "--json", "enable"])["ok"], true);
    let rec = json(
        &bin,
        &dir,
        &[
            "board",
            "--port",
            p,
            "--json",
            "record",
            "--seconds",
            "3",
            "--out",
            "rec.csv",
            "--profile",
            "profile.csv",
            "--enable",
        ],
    );
    drop(board);
    // 3 s at every 10th sample of the page's rate; nothing lost on TCP.
    let samples = rec["samples"].as_u64().expect("samples") as f64;
    let want = 3.0 * hz / 10.0;
    assert!(samples >= 0.98 * want && samples <= want, "{rec}");
    assert_eq!(rec["lost_frames"], 0, "{rec}");

    // The recording is fitted as it is (columns t, b, torque).
    let fit = json(&bin, &dir, &["fit", "rec.csv", "--model", model, "--json"]);
    let r2 = fit["results"][0]["heldout"]["r2"].as_f64().expect("r2");
    assert!(r2 > 0.9, "fit of the recorded CSV: held-out R² {r2}");

    // Same core, same numbers: `loop` replays the board's journal.
    let (head, rows) = read_csv(&dir.join("rec.csv"));
    let (ct, ce, cr, ctrue) =
        (col(&head, "t"), col(&head, "torque_est"), col(&head, "reference"), col(&head, "torque"));
    let t_of = |r: &Vec<String>, c: usize| r[c].parse::<f64>().expect("t");
    let last = rows.iter().map(|r| t_of(r, ct)).fold(0.0, f64::max);
    let events = journal(&dir.join("journal.txt"));
    assert!(events.iter().any(|e| e.1 == "page"), "the page was never swapped in");
    let duration = format!("{}", last + 0.75 / hz);
    let replayed = json(
        &bin,
        &dir,
        &["loop", "--replay", "journal.txt", "--params", &fitted, "--trace", "loop.csv"]
            .into_iter()
            .chain(["--duration", &duration, "--json"])
            .collect::<Vec<_>>(),
    );
    assert_eq!(replayed["page_crc"], exported["crc"], "{replayed}");
    assert_eq!(replayed["control_hz"].as_f64(), Some(hz), "{replayed}");
    let (lhead, lrows) = read_csv(&dir.join("loop.csv"));
    let (lt, le, ltrue) = (col(&lhead, "t"), col(&lhead, "torque_est"), col(&lhead, "torque"));
    let ltimes: Vec<f64> = lrows.iter().map(|r| t_of(r, lt)).collect();
    assert_eq!(replayed["samples"].as_u64(), Some(lrows.len() as u64), "{replayed}");
    let mut driven = 0;
    for r in &rows {
        let t = t_of(r, ct);
        // The loop's sample at the recorded time (both count time per period from 0).
        let k = ltimes.partition_point(|&lt| lt < t - 0.25 / hz);
        let l = lrows.get(k).unwrap_or_else(|| panic!("loop.csv ends before t = {t}"));
        assert!((ltimes[k] - t).abs() < 0.25 / hz, "recorded t {t}: the loop has a sample at {}", ltimes[k]);
        let est: f32 = r[ce].parse().expect("torque_est");
        let again: f32 = l[le].parse().expect("loop torque_est");
        assert_eq!(est.to_bits(), again.to_bits(), "t = {t}: recorded {est}, loop {again}");
        let tru: f32 = r[ctrue].parse().expect("torque");
        assert_eq!(tru.to_bits(), l[ltrue].parse::<f32>().expect("loop torque").to_bits(), "t = {t}: true torque");
        if r[cr].parse::<f64>().expect("reference") > 1.0 && est > 1.0 {
            driven += 1;
        }
    }
    // The comparison covers a driven clutch, not a board at rest.
    assert!(driven > rows.len() / 2, "only {driven} of {} samples with the clutch driven", rows.len());
}

#[test]
fn an_injected_hall_fault_is_in_status_within_2_ms() {
    let bin = hil_sim();
    let dir = scratch("fault");
    let board = virtual_board(&bin, &dir, &["--fault", "hall_open@1.0", "--journal", "journal.txt"]);
    let p = board.port.as_str();
    let args =
        ["board", "--port", p, "--json", "record", "--seconds", "1.5", "--decimate", "1", "--out", "f.csv", "--enable"];
    let out = Command::new(&bin).current_dir(&dir).args(args).output().expect("running hil-sim");
    // The board left closed loop: the recording ends there, kept as a partial file.
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "a recording that lost closed loop exited 0");
    assert!(err.contains("left closed loop") && err.contains("hall_open") && err.contains("f.partial.csv"), "{err}");
    assert!(!dir.join("f.csv").exists(), "a cut recording is not written as a whole one");
    let note = std::fs::read_to_string(dir.join("f.partial.txt")).expect("the partial file's note");
    assert!(note.contains("left closed loop"), "{note}");
    let status = json(&bin, &dir, &["board", "--port", p, "--json", "status"]);
    drop(board);
    let enabled_at = journal(&dir.join("journal.txt"))
        .iter()
        .find(|e| e.1 == "enable" && e.2 == "1")
        .map(|e| e.0 as f64 / 20_000.0)
        .expect("enable in the journal");
    assert!(enabled_at < 0.8, "the board was enabled at {enabled_at} s, too late for a fault at 1.0 s (slow machine?)");
    let (head, rows) = read_csv(&dir.join("f.partial.csv"));
    let (ct, cf) = (col(&head, "t"), col(&head, "fault"));
    let first = rows.iter().find(|r| r[cf] != "0").expect("the fault shows up in the recording");
    let t: f64 = first[ct].parse().expect("t");
    assert!((1.0..=1.002).contains(&t), "hall_open latched at {t} s (injected at 1.0 s)");
    let code = u64::from(model_core::control::FaultCode::HallOpen.code());
    assert_eq!(first[cf], code.to_string(), "{first:?}");
    assert_eq!(status["fault"], code, "{status}");
    assert_eq!(status["fault_name"], "hall_open", "{status}");
}

#[test]
fn a_stalled_task_starves_the_watchdog_and_the_board_resets_and_answers_again() {
    let bin = hil_sim();
    let dir = scratch("stall");
    let board = virtual_board(&bin, &dir, &["--stall-tasks", "0.5"]);
    let wait = std::time::Instant::now() + std::time::Duration::from_secs(30);
    let line = loop {
        let left = wait.saturating_duration_since(std::time::Instant::now());
        let l = board.log.recv_timeout(left).expect("a watchdog reset on stderr within 30 s");
        if l.contains("watchdog reset at") {
            break l;
        }
    };
    let t: f64 = line
        .split("watchdog reset at ")
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no time in `{line}`"));
    // The watchdog task pets every 10 ms; the watchdog expires 50 ms after the last pet.
    assert!((0.54..=0.551).contains(&t), "reset at {t} s for tasks stalled at 0.5 s: {line}");
    assert!(line.contains("IndependentWatchdog"), "{line}");
    let status = json(&bin, &dir, &["board", "--port", &board.port, "--json", "status"]);
    assert_eq!(status["fault"], 0, "the board answers again after the reset: {status}");
}
