//! The board link under faults: a misbehaving host against the virtual board (which runs
//! the firmware's own command task, `firmware::application`), and a misbehaving board
//! against `hil-sim board`. Each case states what must hold; together they are the rules
//! of `model_core::protocol::session` and of `hil_sim::link` seen from outside:
//! a command that was not acknowledged has not happened, one host controls the board,
//! faults are seen in every mode, a recording is whole or kept as a partial file that
//! says why, a commit left unanswered says which page runs, absurd values never leave
//! the host.

use std::net::TcpStream;
use std::path::Path;
use std::process::Command as Process;
use std::time::{Duration, Instant};

use integration_tests::board::{col, fail, hil_sim, journal, journal_has, json, read_csv, run, scratch, virtual_board};
use integration_tests::peer::{framed, RawHost, Script, ScriptedBoard};
use model_core::protocol::telemetry::Telemetry;
use model_core::protocol::{Command, Nack, Response};

const MS: Duration = Duration::from_millis(1);

fn nack_of(r: Option<Response>) -> Option<Nack> {
    match r {
        Some(Response::Nack { why, .. }) => Some(why),
        _ => None,
    }
}

/// A valid clutch set: the algebraic model with seed 000's average parameters.
fn clutch_set(dir: &Path) -> std::path::PathBuf {
    let p = dir.join("clutch.json");
    let params: Vec<String> = model_core::models::algebraic::SEED000_AVERAGE.iter().map(|v| v.to_string()).collect();
    std::fs::write(&p, format!("{{\"model\":\"algebraic\",\"params\":[{}]}}", params.join(","))).expect("set");
    p
}

#[test]
fn a_command_the_host_did_not_see_acknowledged_never_runs_later() {
    let bin = hil_sim();
    let dir = scratch("late");
    let board = virtual_board(&bin, &dir, &["--journal", "j.txt"]);
    let j = dir.join("j.txt");
    // A host that connects and says nothing stands between the board and no one.
    let silent = TcpStream::connect(board.port.strip_prefix("tcp:").expect("tcp")).expect("silent host");
    // The CLI's commands while the silent host stays connected: acknowledged and run.
    let t = json(&bin, &dir, &["board", "--port", &board.port, "--json", "torque", "4"]);
    assert_eq!(t["ok"], true);
    run(&bin, &dir, &["board", "--port", &board.port, "enable"]);
    let mut h = RawHost::connect(&board.port);
    let g = h.claim(0x0A11).expect("a session");
    // Held back past its deadline (a stalled host, a buffering line): refused, never run.
    let late = h.due(g, 50);
    std::thread::sleep(200 * MS);
    h.send(Command::SetTorque { guard: late, reference: 7.5, ack: true });
    assert_eq!(nack_of(h.reply(2000 * MS, |r| matches!(r, Response::Nack { .. }))), Some(Nack::Expired));
    // The same command twice, or an older one after a newer: the second never runs.
    let g2 = h.due(late.next(0), 300);
    h.send(Command::SetTorque { guard: g2, reference: 2.5, ack: true });
    assert!(matches!(
        h.reply(2000 * MS, |r| matches!(r, Response::Ack { .. } | Response::Nack { .. })),
        Some(Response::Ack { .. })
    ));
    h.send(Command::SetTorque { guard: g2, reference: 2.5, ack: true });
    assert_eq!(nack_of(h.reply(2000 * MS, |r| matches!(r, Response::Nack { .. }))), Some(Nack::Stale));
    let g3 = h.due(g2.next(0), 300);
    let g4 = h.due(g3.next(0), 300);
    h.send(Command::SetTorque { guard: g4, reference: 3.5, ack: false });
    h.send(Command::SetTorque { guard: g3, reference: 9.5, ack: true });
    assert_eq!(nack_of(h.reply(2000 * MS, |r| matches!(r, Response::Nack { .. }))), Some(Nack::Stale), "overtaken");
    h.send(Command::Release { guard: h.due(g4.next(0), 300) });
    h.replies(100 * MS);
    drop(silent);
    std::thread::sleep(300 * MS);
    drop(board);
    assert!(journal_has(&j, "ref", "4"), "an acknowledged torque ran");
    assert!(journal_has(&j, "enable", "1"), "an acknowledged enable ran");
    assert!(journal_has(&j, "ref", "2.5"));
    assert!(!journal_has(&j, "ref", "7.5"), "the expired command ran: {:?}", journal(&j));
    assert!(!journal_has(&j, "ref", "9.5"), "the overtaken command ran: {:?}", journal(&j));
}

#[test]
fn one_host_controls_the_others_read_and_are_told_busy_and_a_silent_holder_times_out() {
    let bin = hil_sim();
    let dir = scratch("busy");
    let board = virtual_board(&bin, &dir, &["--journal", "j.txt"]);
    let port = board.port.clone();
    let t0 = Instant::now();
    let holder = std::thread::spawn(move || {
        let mut h = RawHost::connect(&port);
        let mut g = h.claim(0xB0B).expect("the first claim is granted");
        // Heartbeats for 2.5 s, then silence (connected, saying nothing).
        let end = Instant::now() + 2500 * MS;
        h.replies(20 * MS);
        while Instant::now() < end {
            g = h.due(g.next(0), 100);
            h.send(Command::Heartbeat { guard: g });
            h.replies(50 * MS);
        }
        std::thread::sleep(3000 * MS);
        h
    });
    std::thread::sleep(300 * MS);
    let err = fail(&bin, &dir, &["board", "--port", &board.port, "enable"]);
    assert!(err.contains("controlled by another host"), "{err}");
    let status = json(&bin, &dir, &["board", "--port", &board.port, "--json", "status"]);
    assert_eq!(status["mode_name"], "disabled", "another host may read while one holds the board: {status}");
    // The holder falls silent at 2.5 s; its session ends 1 s later, and the next claim is
    // granted.
    std::thread::sleep((t0 + 3700 * MS).saturating_duration_since(Instant::now()));
    run(&bin, &dir, &["board", "--port", &board.port, "enable"]);
    drop(holder.join().expect("holder"));
    drop(board);
    let enables = journal(&dir.join("j.txt")).iter().filter(|e| e.1 == "enable" && e.2 == "1").count();
    assert_eq!(enables, 1, "only the enable acknowledged ran");
}

#[test]
fn a_recording_that_loses_closed_loop_ends_with_an_error_and_keeps_its_samples() {
    let bin = hil_sim();
    let dir = scratch("paused");
    let board = virtual_board(&bin, &dir, &[]);
    let child = Process::new(&bin)
        .current_dir(&dir)
        .args(["board", "--port", &board.port, "record", "--seconds", "3", "--out", "r.csv", "--enable"])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("record");
    std::thread::sleep(1200 * MS);
    // The host stops for 0.3 s (a laptop under load, a debugger): the board releases the
    // drive after its 100 ms command timeout.
    let pid = child.id() as i32;
    // SAFETY: signals to our own child process.
    unsafe { libc::kill(pid, libc::SIGSTOP) };
    std::thread::sleep(300 * MS);
    unsafe { libc::kill(pid, libc::SIGCONT) };
    let out = child.wait_with_output().expect("record ends");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "a recording that lost closed loop exited 0: {err}");
    assert!(err.contains("left closed loop") && err.contains("r.partial.csv"), "{err}");
    assert!(!dir.join("r.csv").exists(), "no whole-looking recording");
    let (head, rows) = read_csv(&dir.join("r.partial.csv"));
    let m = col(&head, "mode");
    assert!(rows.iter().filter(|r| r[m] == "2").count() > 1000, "the closed-loop samples are kept");
    assert_ne!(rows.last().expect("rows")[m], "2", "the partial file ends where closed loop ended");
    drop(board);
}

#[test]
fn a_board_reset_mid_recording_keeps_what_was_recorded() {
    let bin = hil_sim();
    let dir = scratch("reset");
    let board = virtual_board(&bin, &dir, &["--stall-tasks", "1.5"]);
    let err = fail(&bin, &dir, &["board", "--port", &board.port, "record", "--seconds", "4", "--out", "r.csv"]);
    assert!(err.contains("r.partial.csv"), "{err}");
    let note = std::fs::read_to_string(dir.join("r.partial.txt")).expect("the note");
    assert!(note.contains("ended because"), "{note}");
    let (head, rows) = read_csv(&dir.join("r.partial.csv"));
    let t = col(&head, "t");
    let last: f64 = rows.last().expect("samples kept")[t].parse().expect("t");
    assert!((1.0..=1.51).contains(&last), "recorded up to {last} s, the tasks stalled at 1.5 s");
    assert!(!dir.join("r.csv").exists());
}

#[test]
fn a_latched_fault_is_seen_with_the_bridge_off_and_enable_and_reset_say_so() {
    let bin = hil_sim();
    let dir = scratch("idle-fault");
    let board = virtual_board(&bin, &dir, &["--fault", "hall_open@2.0", "--journal", "j.txt"]);
    let p = board.port.as_str();
    // Nobody drives: the recording runs through the fault.
    let rec = json(
        &bin,
        &dir,
        &["board", "--port", p, "--json", "record", "--seconds", "2.5", "--decimate", "1", "--out", "f.csv"],
    );
    assert_eq!(rec["lost_frames"], 0, "{rec}");
    let (head, rows) = read_csv(&dir.join("f.csv"));
    let (ct, cf, cm) = (col(&head, "t"), col(&head, "fault"), col(&head, "mode"));
    let t0: f64 = rows[0][ct].parse().expect("t");
    assert!(t0 < 2.0, "the recording started at {t0} s, after the fault (slow machine?)");
    let first = rows.iter().find(|r| r[cf] != "0").expect("the fault is latched with the bridge off");
    let t: f64 = first[ct].parse().expect("t");
    assert!((2.0..=2.002).contains(&t), "hall_open latched at {t} s with the bridge off (injected at 2.0 s)");
    assert!(rows.iter().all(|r| r[cm] != "2"), "the bridge stayed off");
    let status = json(&bin, &dir, &["board", "--port", p, "--json", "status"]);
    assert_eq!(status["fault_name"], "hall_open", "{status}");
    let err = fail(&bin, &dir, &["board", "--port", p, "enable"]);
    assert!(err.contains("fault is latched") && err.contains("hall_open"), "{err}");
    let err = fail(&bin, &dir, &["board", "--port", p, "reset"]);
    assert!(err.contains("still present") && err.contains("hall_open"), "{err}");
    drop(board);
    assert!(!journal_has(&dir.join("j.txt"), "enable", "1"), "the refused enable did not run");
}

#[test]
fn absurd_values_are_refused_at_the_host_with_the_limit_named() {
    let bin = hil_sim();
    let dir = scratch("absurd");
    let board = virtual_board(&bin, &dir, &["--journal", "j.txt"]);
    let p = board.port.as_str();
    for v in ["1e38", "NaN", "-40000"] {
        let err = fail(&bin, &dir, &["board", "--port", p, "torque", "--", v]);
        assert!(err.contains("limit of ±") || err.contains("not a number") || err.contains("invalid"), "{v}: {err}");
    }
    std::fs::write(dir.join("p.csv"), "t,reference\n0,1\n0.5,1e39\n1,2\n").expect("profile");
    let err = fail(
        &bin,
        &dir,
        &["board", "--port", p, "record", "--seconds", "1", "--out", "r.csv", "--profile", "p.csv", "--enable"],
    );
    assert!(err.contains("row 2") && err.contains("limit of ±"), "{err}");
    let err = fail(&bin, &dir, &["board", "--port", p, "record", "--seconds", "1e-9", "--out", "r.csv"]);
    assert!(err.contains("--seconds"), "{err}");
    drop(board);
    assert!(!journal_has(&dir.join("j.txt"), "ref", ""), "a refused value reached the board");
    assert!(!journal_has(&dir.join("j.txt"), "enable", "1"), "the clutch was driven for a refused recording");
}

#[test]
fn outputs_are_checked_before_the_clutch_is_driven() {
    let bin = hil_sim();
    let dir = scratch("outputs");
    let board = virtual_board(&bin, &dir, &["--journal", "j.txt"]);
    let p = board.port.as_str();
    std::fs::write(dir.join("p.csv"), "t,reference\n0,1\n1,2\n").expect("profile");
    let before = std::fs::read(dir.join("p.csv")).expect("profile");
    let err = fail(
        &bin,
        &dir,
        &["board", "--port", p, "record", "--seconds", "1", "--profile", "p.csv", "--out", "p.csv", "--enable"],
    );
    assert!(err.contains("input"), "{err}");
    assert_eq!(std::fs::read(dir.join("p.csv")).expect("profile"), before, "the profile was overwritten");
    std::fs::write(dir.join("target.txt"), "keep").expect("target");
    std::os::unix::fs::symlink(dir.join("target.txt"), dir.join("link.csv")).expect("symlink");
    let err = fail(&bin, &dir, &["board", "--port", p, "record", "--seconds", "1", "--out", "link.csv", "--enable"]);
    assert!(err.contains("symbolic link"), "{err}");
    let err = fail(
        &bin,
        &dir,
        &["board", "--port", p, "record", "--seconds", "1", "--out", "/proc/no/such/x.csv", "--enable"],
    );
    assert!(!err.is_empty());
    // A folder that is not there yet is made, and the recording lands in it.
    run(&bin, &dir, &["board", "--port", p, "record", "--seconds", "0.3", "--out", "missing/dir/x.csv"]);
    assert!(dir.join("missing/dir/x.csv").exists());
    drop(board);
    assert!(!journal_has(&dir.join("j.txt"), "enable", "1"), "the clutch was driven before its output was refused");
    // The journal does not write through a symlink either.
    let out = Process::new(&bin)
        .current_dir(&dir)
        .args(["virtual-board", "--listen", "tcp:127.0.0.1:0", "--journal", "link.csv"])
        .output()
        .expect("virtual board");
    assert!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains("symbolic link"));
    assert_eq!(std::fs::read_to_string(dir.join("target.txt")).expect("target"), "keep");
}

/// A board whose telemetry is scripted frame by frame.
struct Frames<F: FnMut(u64) -> Vec<u8> + Send + 'static>(F);

impl<F: FnMut(u64) -> Vec<u8> + Send + 'static> Script for Frames<F> {
    fn telemetry(&mut self, n: u64) -> Vec<u8> {
        (self.0)(n)
    }
}

fn tele(seq: u16, t_us: u32) -> Vec<u8> {
    framed(&Telemetry { t_us, b: 0.1, mode: 3, torque_true: f32::NAN, ..Telemetry::default() }.encode(seq))
}

#[test]
fn lost_frames_are_counted_exactly_through_duplicates_reordering_and_a_gap() {
    let bin = hil_sim();
    let dir = scratch("lost");
    // Frame k at k·0.5 ms; then a duplicate, a swapped pair, a gap of 5, a stray frame of
    // an old stream. Lost: the 5 of the gap and the one of the pair that came too late to be
    // recorded in order; out of order: the duplicate, the late one, the stray.
    let board = ScriptedBoard::start(
        Frames(|n| {
            let k = n as u16;
            let f = |q: u16| tele(q, u32::from(q) * 500);
            match n {
                100 => [f(99), f(100)].concat(),
                200 => f(201),
                201 => f(200),
                300..=304 => vec![],
                400 => [f(60_000), f(400)].concat(),
                _ => f(k),
            }
        }),
        0,
    );
    let rec =
        json(&bin, &dir, &["board", "--port", &board.port, "--json", "record", "--seconds", "1", "--out", "r.csv"]);
    assert_eq!(rec["lost_frames"], 6, "{rec}");
    assert_eq!(rec["out_of_order"], 3, "{rec}");
    // Every frame between the first and the last recorded is either in the file or lost.
    let (head, rows) = read_csv(&dir.join("r.csv"));
    let t = col(&head, "t");
    let span = |r: &Vec<String>| (r[t].parse::<f64>().expect("t") / 5e-4).round() as u64;
    let (first, last) = (span(&rows[0]), span(rows.last().expect("rows")));
    assert_eq!(rows.len() as u64 + 6, last - first + 1, "frames {first}..={last}");
}

#[test]
fn a_board_that_stops_streaming_or_whose_clock_stops_ends_the_recording() {
    let bin = hil_sim();
    let dir = scratch("stopped");
    let mute = ScriptedBoard::start(Frames(|_| vec![]), 0);
    let t = Instant::now();
    let err = fail(&bin, &dir, &["board", "--port", &mute.port, "record", "--seconds", "2", "--out", "a.csv"]);
    assert!(err.contains("stopped") && err.contains("a.partial.csv"), "{err}");
    assert!(t.elapsed() < Duration::from_secs(6), "took {:?}", t.elapsed());
    let frozen = ScriptedBoard::start(Frames(|n| tele(n as u16, 777)), 0);
    let t = Instant::now();
    let err = fail(&bin, &dir, &["board", "--port", &frozen.port, "record", "--seconds", "1", "--out", "b.csv"]);
    assert!(err.contains("clock stopped"), "{err}");
    assert!(t.elapsed() < Duration::from_secs(6), "took {:?}", t.elapsed());
}

/// A board that never answers the commit; its page query answers `after` once a commit
/// was sent (`None`: it answers nothing any more).
struct SilentCommit {
    committed: bool,
    after: Option<u32>,
}

impl Script for SilentCommit {
    fn on_command(&mut self, cmd: &Command) -> Option<Vec<u8>> {
        match cmd {
            Command::ConfigCommit { .. } => {
                self.committed = true;
                Some(vec![])
            }
            _ if !self.committed => None,
            Command::ConfigQuery => Some(self.after.map_or(vec![], |crc| {
                let mut f = [0u8; 8];
                let n = Response::PageCrc(crc).encode(&mut f);
                framed(&f[..n])
            })),
            _ => Some(vec![]),
        }
    }
    fn telemetry(&mut self, _: u64) -> Vec<u8> {
        vec![]
    }
}

#[test]
fn a_commit_left_unanswered_says_which_page_runs() {
    let bin = hil_sim();
    let dir = scratch("commit");
    let set = clutch_set(&dir);
    let want = {
        let file = hil_sim::io::params_file::ParamsFile::read(&set).expect("set");
        let (_, control) = hil_sim::io::config_page::firmware_control(&file.model, None).expect("control");
        hil_sim::io::config_page::firmware_image(&file, &set, control).expect("image").crc()
    };
    let old = 0x1234_5678;
    let cases = [(Some(want), "ok"), (Some(old), "did not take effect"), (None, "UNKNOWN")];
    let handles: Vec<_> = cases
        .into_iter()
        .map(|(after, expect)| {
            let (bin, dir, set) = (bin.clone(), dir.clone(), set.clone());
            std::thread::spawn(move || {
                let board = ScriptedBoard::start(SilentCommit { committed: false, after }, old);
                let out = Process::new(&bin)
                    .current_dir(&dir)
                    .args(["board", "--port", &board.port, "load"])
                    .arg(&set)
                    .output()
                    .expect("load");
                let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
                assert_eq!(out.status.success(), expect == "ok", "{text}");
                assert!(text.contains(expect), "expected `{expect}`: {text}");
            })
        })
        .collect();
    for h in handles {
        h.join().expect("case");
    }
}

#[test]
fn garbage_half_frames_and_extra_hosts_leave_the_board_answering() {
    let bin = hil_sim();
    let dir = scratch("garbage");
    let board = virtual_board(&bin, &dir, &[]);
    let mut h = RawHost::connect(&board.port);
    // Garbage, a frame cut in half, a frame with a bad CRC: dropped; the next frame is read.
    h.send_raw(&[0x13, 0x77, 0xFF, 0x00, 0x05, 0x01, 0x02]);
    let mut bad = framed(&[0x04]);
    bad[2] ^= 0x40;
    h.send_raw(&bad);
    assert!(h.claim(0x5EED).is_some(), "a claim after the garbage is answered");
    // Four hosts at once are served; a fifth is closed at once.
    let others: Vec<RawHost> = (0..3).map(|_| RawHost::connect(&board.port)).collect();
    std::thread::sleep(50 * MS);
    let mut fifth = RawHost::connect(&board.port);
    let _ = std::io::Write::write_all(&mut fifth.stream, &framed(&[0x04]));
    assert!(fifth.reply(500 * MS, |r| matches!(r, Response::Status { .. })).is_none(), "a fifth host was served");
    drop(others);
    let status = json(&bin, &dir, &["board", "--port", &board.port, "--json", "status"]);
    assert_eq!(status["fault"], 0, "{status}");
}

/// The page `export` would write for the set at `path` (no physics check: what a host that
/// skips it would send).
fn page_of(path: &Path) -> Vec<u8> {
    let file = hil_sim::io::params_file::ParamsFile::read(path).expect("set");
    let (_, control) = hil_sim::io::config_page::firmware_control(&file.model, None).expect("control");
    let page = hil_sim::io::config_page::firmware_image(&file, path, control).expect("image").encode();
    let used = usize::from(u16::from_le_bytes([page[6], page[7]])) + 4;
    page[..used].to_vec()
}

#[test]
fn a_page_that_would_drive_the_clutch_wrongly_never_reaches_the_loop() {
    let bin = hil_sim();
    let dir = scratch("physics");
    let board = virtual_board(&bin, &dir, &["--journal", "j.txt"]);
    let p = board.port.as_str();
    let [k, c, alpha, t0] = model_core::models::algebraic::SEED000_AVERAGE;
    let flipped = dir.join("flipped.json");
    std::fs::write(&flipped, format!("{{\"model\":\"algebraic\",\"params\":[{},{c},{alpha},{t0}]}}", -k)).expect("set");
    // The host refuses it before sending anything.
    let err = fail(&bin, &dir, &["board", "--port", p, "load", "flipped.json"]);
    assert!(err.contains("refused: the estimate decreases as the field rises"), "{err}");
    // A host that skips the check: the board refuses the commit itself.
    let mut h = RawHost::connect(p);
    let g = h.claim(0xFA11).expect("a session");
    h.replies(20 * MS);
    let page = page_of(&flipped);
    h.send(Command::ConfigBegin { guard: h.due(g, 300), len: page.len() as u16 });
    assert!(h.reply(1000 * MS, |r| matches!(r, Response::Ack { code: 0x10, .. })).is_some());
    for (i, chunk) in page.chunks(5).enumerate() {
        let mut data = [0u8; 5];
        data[..chunk.len()].copy_from_slice(chunk);
        h.send(Command::ConfigData { offset: (i * 5) as u16, len: chunk.len() as u8, data });
    }
    let crc = !model_core::control::config::crc32_update(!0, &page);
    h.send(Command::ConfigCommit { crc });
    let reply =
        h.reply(5000 * MS, |r| matches!(r, Response::Ack { code: 0x12, .. } | Response::Nack { code: 0x12, .. }));
    assert_eq!(nack_of(reply), Some(Nack::Physics), "{reply:?}");
    h.send(Command::Release { guard: h.due(g.next(0), 300) });
    drop(h);
    // A clutch set loads.
    let set = clutch_set(&dir);
    let out = run(&bin, &dir, &["board", "--port", p, "load", set.to_str().expect("path")]);
    assert!(out.contains("committed and verified"), "{out}");
    std::thread::sleep(100 * MS);
    drop(board);
    let pages: Vec<_> = journal(&dir.join("j.txt")).into_iter().filter(|e| e.1 == "page").collect();
    assert_eq!(pages.len(), 1, "only the clutch set reached the loop: {pages:?}");
}

#[test]
fn deadlines_follow_a_board_clock_that_runs_fast_over_a_long_driven_recording() {
    let bin = hil_sim();
    let dir = scratch("drift");
    // A board clock 5 % fast: without reading it again the host's deadlines would fall
    // behind it by more than a set-point's 100 ms lead within 2 s.
    let board = ScriptedBoard::with_clock(Frames(|n| tele(n as u16, (n as u32) * 500)), 0, 1.05);
    std::fs::write(dir.join("p.csv"), "t,reference\n0,1\n4,2\n").expect("profile");
    let rec = json(
        &bin,
        &dir,
        &["board", "--port", &board.port, "--json", "record", "--seconds", "4", "--out", "r.csv", "--profile", "p.csv"],
    );
    assert!(rec["samples"].as_u64().expect("samples") > 7000, "{rec}");
}
