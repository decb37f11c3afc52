//! Issue 17 acceptance 2: the board protocol over a pseudo-terminal pair (a real serial byte
//! stream: `hil-sim`'s `Link` opens the tty with the `serialport` crate as it opens
//! /dev/ttyACM0), with random garbage and dropped bytes injected on the line in both
//! directions. The board end runs the firmware's command handling
//! (`model_core::protocol::device::Device`) and streams numbered telemetry. Checked: no
//! command is misread (every torque reference the board decodes is one the host sent, in
//! order), every telemetry frame the host receives is intact, every frame lost on the line is
//! counted (the host's count equals the frames the injector damaged), and once the noise
//! stops the link answers again.

use std::fs::File;
use std::io::{ErrorKind, Read, Write};
use std::os::fd::{FromRawFd, OwnedFd};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use hil_sim::link::Link;
use model_core::protocol::device::{Action, Device, StatusFigures};
use model_core::protocol::frame::{encode, Deframer, MAX_ENCODED};
use model_core::protocol::telemetry::Telemetry;
use model_core::protocol::{Command, Sessions, FRAME};

/// A pseudo-terminal pair in raw mode: the master end and the slave's path.
fn openpty() -> (File, PathBuf, OwnedFd) {
    let (mut m, mut s) = (0, 0);
    let mut name = [0 as libc::c_char; 128];
    // SAFETY: openpty writes two descriptors and a NUL-terminated name of at most 128 bytes
    // into the buffers given; the termios and winsize pointers may be null.
    let rc = unsafe { libc::openpty(&mut m, &mut s, name.as_mut_ptr(), std::ptr::null(), std::ptr::null()) };
    assert_eq!(rc, 0, "openpty failed");
    // SAFETY: both descriptors were just opened by openpty and are owned here.
    let (master, slave) = unsafe { (File::from_raw_fd(m), OwnedFd::from_raw_fd(s)) };
    // SAFETY: tcgetattr/cfmakeraw/tcsetattr on a valid descriptor with a termios on the stack.
    unsafe {
        for fd in [m, s] {
            let mut t: libc::termios = std::mem::zeroed();
            assert_eq!(libc::tcgetattr(fd, &mut t), 0);
            libc::cfmakeraw(&mut t);
            assert_eq!(libc::tcsetattr(fd, libc::TCSANOW, &t), 0);
        }
        let flags = libc::fcntl(m, libc::F_GETFL);
        assert_eq!(libc::fcntl(m, libc::F_SETFL, flags | libc::O_NONBLOCK), 0);
    }
    // SAFETY: name is NUL-terminated by openpty.
    let path = unsafe { std::ffi::CStr::from_ptr(name.as_ptr()) }.to_string_lossy().into_owned();
    (master, PathBuf::from(path), slave)
}

/// xorshift64*: reproducible noise.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn chance(&mut self, p: f64) -> bool {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64 <= p
    }
}

/// The line: drops bytes and inserts garbage (never 0x00, so a frame's fate is known:
/// damaged frames are exactly those the receiver loses) while `noisy`.
struct Line {
    rng: Rng,
    p: f64,
}

impl Line {
    /// Pass one encoded frame; true when it was damaged on the way (a byte dropped or one
    /// inserted in it or in the gap before it, or the previous delimiter dropped).
    fn pass(&mut self, frame: &[u8], noisy: bool, prev_cut: &mut bool, out: &mut Vec<u8>) -> bool {
        let mut damaged = std::mem::take(prev_cut);
        for (i, &b) in frame.iter().enumerate() {
            if noisy && self.rng.chance(self.p) {
                let n = 1 + self.rng.next() % 6;
                out.extend((0..n).map(|_| 1 + (self.rng.next() % 255) as u8));
                damaged = true;
            }
            if noisy && self.rng.chance(self.p) {
                damaged = true;
                if i + 1 == frame.len() {
                    *prev_cut = true;
                }
                continue;
            }
            out.push(b);
        }
        damaged
    }
}

#[derive(Default)]
struct BoardLog {
    references: Vec<f32>,
    /// Telemetry sequence numbers sent, and which of them the line damaged.
    sent: Vec<(u16, bool)>,
}

fn board(master: File, noisy: Arc<AtomicBool>, stop: Arc<AtomicBool>, log: Arc<Mutex<BoardLog>>) {
    let mut master = master;
    let mut device = Device::default();
    let mut sessions = Sessions::new();
    let started = std::time::Instant::now();
    let mut deframer = Deframer::default();
    let (mut up, mut down) = (Line { rng: Rng(0x9E37_79B9_7F4A_7C15), p: 0.004 }, Line { rng: Rng(7), p: 0.004 });
    let (mut up_cut, mut down_cut) = (false, false);
    let mut reference = 0.0f32;
    let mut buf = [0u8; 512];
    let mut tick = 0u32;
    while !stop.load(Ordering::Relaxed) {
        let noise = noisy.load(Ordering::Relaxed);
        let mut out = Vec::new();
        match master.read(&mut buf) {
            Ok(n) => {
                // The host's bytes cross the line too (damage there is seen as lost replies).
                let mut rx = Vec::new();
                let _ = down.pass(&buf[..n], noise, &mut down_cut, &mut rx);
                for b in rx {
                    let Some(Ok(p)) = deframer.push(b) else { continue };
                    let p = p.to_vec();
                    let now_ms = started.elapsed().as_millis() as u64;
                    let h = device.handle(&p, now_ms, &mut sessions);
                    let reply = match h.action {
                        Action::Reference { value, reply } => {
                            reference = value;
                            log.lock().unwrap().references.push(value);
                            reply.map(|r| r.ack())
                        }
                        Action::Status => {
                            Some(device.status(StatusFigures { mode: 2, fault: 0, overruns: 0, torque_est: reference }))
                        }
                        _ => h.reply,
                    };
                    if let Some(r) = reply {
                        let mut f = [0u8; FRAME];
                        let n = r.encode(&mut f);
                        let mut e = [0u8; MAX_ENCODED];
                        let m = encode(&f[..n], &mut e);
                        let _ = up.pass(&e[..m], noise, &mut up_cut, &mut out);
                    }
                }
            }
            Err(e) if e.kind() == ErrorKind::WouldBlock => {}
            Err(_) => break,
        }
        // Telemetry at every call while streaming (about 2 kHz), time = sequence × 0.5 ms.
        if device.telemetry_due() {
            let seq = device.next_seq();
            let t = Telemetry {
                t_us: u32::from(seq) * 500,
                b: f32::from(seq) * 1e-3,
                torque_est: reference,
                reference,
                ..Telemetry::default()
            };
            let mut e = [0u8; MAX_ENCODED];
            let m = encode(&t.encode(seq), &mut e);
            let damaged = up.pass(&e[..m], noise, &mut up_cut, &mut out);
            log.lock().unwrap().sent.push((seq, damaged));
        }
        if !out.is_empty() {
            let _ = master.write_all(&out);
        }
        tick = tick.wrapping_add(1);
        std::thread::sleep(Duration::from_micros(500));
    }
}

#[test]
fn garbage_and_dropped_bytes_on_a_tty_are_caught_counted_and_survived() {
    let (master, path, _slave) = openpty();
    let (noisy, stop) = (Arc::new(AtomicBool::new(true)), Arc::new(AtomicBool::new(false)));
    let log = Arc::new(Mutex::new(BoardLog::default()));
    let th = {
        let (n, s, l) = (noisy.clone(), stop.clone(), log.clone());
        std::thread::spawn(move || board(master, n, s, l))
    };
    let mut link = Link::open(path.to_str().expect("path")).expect("opening the tty as a serial port");

    // Commands under noise: distinct references, each followed by a status request.
    let mut sent = Vec::new();
    let mut answered = 0;
    for i in 0..150 {
        let v = i as f32 + 0.25;
        link.stream_command(|guard| Command::SetTorque { guard, reference: v, ack: false }).expect("send");
        sent.push(v);
        if let Ok(s) = link.status() {
            answered += 1;
            // A status carries the board's reference: one the host sent, never a mangled one.
            assert!(s.torque_estimate == 0.0 || sent.contains(&s.torque_estimate), "{s:?}");
        }
    }
    // Telemetry under noise.
    link.stream(1).expect("telemetry on (retried through the noise)");
    let mut got: Vec<Telemetry> = Vec::new();
    while got.len() < 2000 {
        got.extend(link.telemetry(Duration::from_secs(5), "streaming").expect("telemetry"));
    }
    noisy.store(false, Ordering::Relaxed);
    link.stream(0).expect("telemetry off");
    // Recovered: a clean exchange once the noise stops.
    let s = link.status().expect("status after the noise");
    stop.store(true, Ordering::Relaxed);
    th.join().expect("board thread");

    let log = log.lock().unwrap();
    // No command misread: every reference decoded is one sent, in the order sent.
    assert!(!log.references.is_empty());
    assert!(log.references.iter().all(|r| sent.contains(r)), "a reference the host never sent was decoded");
    assert!(log.references.windows(2).all(|w| w[0] < w[1]), "references out of order");
    assert!(log.references.len() < sent.len() || answered == sent.len(), "the noise damaged nothing on the way in");
    assert_eq!(s.torque_estimate, *log.references.last().unwrap());
    // Every telemetry frame received is intact (its fields agree with its time stamp).
    let seqs: Vec<u16> = got.iter().map(|t| (t.t_us / 500) as u16).collect();
    for t in &got {
        assert_eq!(t.b, ((t.t_us / 500) as u16) as f32 * 1e-3, "{t:?}");
    }
    // Every frame lost between the first and the last received is counted, and only those.
    let (first, last) = (seqs[0], *seqs.last().unwrap());
    let between: Vec<&(u16, bool)> = log.sent.iter().filter(|(q, _)| (first..=last).contains(q)).collect();
    let damaged = between.iter().filter(|(_, d)| *d).count() as u64;
    assert!(damaged > 10, "the injector damaged only {damaged} telemetry frames");
    assert_eq!(got.len() as u64 + damaged, between.len() as u64);
    assert_eq!(
        link.stats.telemetry_lost, damaged,
        "lost frames counted {} (damaged {damaged})",
        link.stats.telemetry_lost
    );
    assert!(link.stats.crc_errors > 0);
}
