//! Misbehaving peers for the fault-injection suite: a raw host that speaks the protocol
//! frame by frame (and can send what no well-behaved host sends: late, repeated,
//! reordered, half frames, then silence), and a scripted board on a TCP port that answers
//! as the firmware does except where its script says otherwise.

use std::io::{ErrorKind, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use model_core::protocol::device::{Action, Device, StatusFigures};
use model_core::protocol::frame::{encode, Deframer, MAX_ENCODED};
use model_core::protocol::{Command, Guard, Response, Sessions, FRAME};

/// `payload` framed for the byte stream (leading delimiter, COBS, CRC, delimiter).
pub fn framed(payload: &[u8]) -> Vec<u8> {
    let mut e = [0u8; MAX_ENCODED];
    let n = encode(payload, &mut e);
    let mut v = vec![0];
    v.extend_from_slice(&e[..n]);
    v
}

/// A command's frame bytes.
pub fn command_bytes(c: Command) -> Vec<u8> {
    let mut f = [0u8; FRAME];
    let n = c.encode(&mut f);
    f[..n].to_vec()
}

/// A host on a raw socket.
pub struct RawHost {
    pub stream: TcpStream,
    deframer: Deframer,
    /// The board's clock from the last ack/nack/session reply, and when it came.
    clock: Option<(u16, Instant)>,
}

impl RawHost {
    pub fn connect(port: &str) -> Self {
        let addr = port.strip_prefix("tcp:").expect("tcp: port");
        let stream = TcpStream::connect(addr).expect("connect");
        stream.set_read_timeout(Some(Duration::from_millis(5))).expect("timeout");
        stream.set_nodelay(true).expect("nodelay");
        Self { stream, deframer: Deframer::default(), clock: None }
    }

    pub fn send_raw(&mut self, bytes: &[u8]) {
        self.stream.write_all(bytes).expect("write");
    }

    pub fn send(&mut self, c: Command) {
        let b = framed(&command_bytes(c));
        self.send_raw(&b);
    }

    /// Replies (not telemetry) received within `wait`.
    pub fn replies(&mut self, wait: Duration) -> Vec<Response> {
        let end = Instant::now() + wait;
        let mut out = Vec::new();
        let mut buf = [0u8; 4096];
        while Instant::now() < end {
            match self.stream.read(&mut buf) {
                Ok(0) => break,
                Ok(n) => {
                    for &b in &buf[..n] {
                        if let Some(Ok(p)) = self.deframer.push(b) {
                            if let Some(r) = Response::decode(p) {
                                if let Response::Ack { now_ms, .. }
                                | Response::Nack { now_ms, .. }
                                | Response::Session { now_ms, .. } = r
                                {
                                    self.clock = Some((now_ms, Instant::now()));
                                }
                                out.push(r);
                            }
                        }
                    }
                }
                Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {}
                // Closed by the board.
                Err(_) => break,
            }
        }
        out
    }

    /// The first reply `pick` takes within `wait`.
    pub fn reply(&mut self, wait: Duration, pick: impl Fn(&Response) -> bool) -> Option<Response> {
        let end = Instant::now() + wait;
        while Instant::now() < end {
            if let Some(r) = self.replies(Duration::from_millis(20)).into_iter().find(|r| pick(r)) {
                return Some(r);
            }
        }
        None
    }

    /// Claim with `nonce`: the guard of the first command (deadline not yet set).
    pub fn claim(&mut self, nonce: u16) -> Option<Guard> {
        self.send(Command::Claim { nonce });
        match self.reply(Duration::from_secs(2), |r| {
            matches!(r, Response::Session { .. } | Response::Nack { code: 0x06, .. })
        }) {
            Some(Response::Session { tag, .. }) => Some(Guard::from_tag(tag, 0)),
            _ => None,
        }
    }

    /// The board's clock now, as followed from its replies, ms (mod 2^16).
    pub fn board_ms(&self) -> u16 {
        let (ms, at) = self.clock.expect("a reply with the board's clock first");
        ms.wrapping_add(at.elapsed().as_millis() as u16)
    }

    /// `g` with a deadline `lead_ms` ahead of the board's clock.
    pub fn due(&self, g: Guard, lead_ms: u16) -> Guard {
        Guard { deadline_ms: self.board_ms().wrapping_add(lead_ms), ..g }
    }
}

/// How a scripted board deviates from the firmware, frame by frame.
pub trait Script: Send + 'static {
    /// A frame from the host: `None` to answer as the firmware would, `Some(bytes)` to send
    /// these raw bytes instead (empty: say nothing).
    fn on_command(&mut self, _cmd: &Command) -> Option<Vec<u8>> {
        None
    }
    /// Called every 0.5 ms while the host has asked for telemetry (`n` frames sent so
    /// far): the raw bytes to send (empty: nothing).
    fn telemetry(&mut self, n: u64) -> Vec<u8>;
}

/// A scripted board listening on a free port; stopped on drop.
pub struct ScriptedBoard {
    pub port: String,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl Drop for ScriptedBoard {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl ScriptedBoard {
    /// Serve one host at a time with `script`; status and page-CRC answers as given.
    pub fn start(script: impl Script, page_crc: u32) -> Self {
        Self::with_clock(script, page_crc, 1.0)
    }

    /// [`ScriptedBoard::start`] with a board clock that runs `rate` times real time (a
    /// crystal off its frequency).
    pub fn with_clock(mut script: impl Script, page_crc: u32, rate: f64) -> Self {
        let listener = TcpListener::bind("127.0.0.1:0").expect("bind");
        listener.set_nonblocking(true).expect("nonblocking");
        let port = format!("tcp:{}", listener.local_addr().expect("addr"));
        let stop = Arc::new(AtomicBool::new(false));
        let s = stop.clone();
        let thread = std::thread::spawn(move || {
            let start = Instant::now();
            let mut sessions = Sessions::new();
            while !s.load(Ordering::Relaxed) {
                let Ok((mut conn, _)) = listener.accept() else {
                    std::thread::sleep(Duration::from_millis(2));
                    continue;
                };
                conn.set_nonblocking(true).expect("nonblocking");
                let mut device = Device::with_active_crc(page_crc);
                let mut deframer = Deframer::default();
                let (mut streaming, mut n, mut buf) = (false, 0u64, [0u8; 4096]);
                let mut next = Instant::now();
                'conn: while !s.load(Ordering::Relaxed) {
                    let mut out = Vec::new();
                    loop {
                        match conn.read(&mut buf) {
                            Ok(0) => break 'conn,
                            Ok(k) => {
                                for &b in &buf[..k] {
                                    let Some(Ok(p)) = deframer.push(b) else { continue };
                                    let p = p.to_vec();
                                    let now_ms = (start.elapsed().as_secs_f64() * 1e3 * rate) as u64;
                                    let cmd = Command::decode(&p);
                                    if let Ok(Command::Telemetry { decimation }) = cmd {
                                        streaming = decimation != 0;
                                    }
                                    if let Some(raw) = cmd.as_ref().ok().and_then(|c| script.on_command(c)) {
                                        // The script answers; the device still sees the frame.
                                        let _ = device.handle(&p, now_ms, &mut sessions);
                                        out.extend(raw);
                                        continue;
                                    }
                                    let h = device.handle(&p, now_ms, &mut sessions);
                                    let r = match h.action {
                                        Action::Status => Some(device.status(StatusFigures::default())),
                                        Action::Limits => {
                                            Some(Response::Limits { reference_max: 30.0, control_hz: 2000 })
                                        }
                                        Action::Commit => Some(device.committed(Ok(()), now_ms)),
                                        Action::Enable { reply, .. }
                                        | Action::Reset { reply }
                                        | Action::Released { reply } => Some(reply.ack()),
                                        Action::Reference { reply, .. } => reply.map(|r| r.ack()),
                                        Action::None => h.reply,
                                    };
                                    if let Some(r) = r {
                                        let mut f = [0u8; FRAME];
                                        let m = r.encode(&mut f);
                                        out.extend(framed(&f[..m]));
                                    }
                                }
                            }
                            Err(e) if e.kind() == ErrorKind::WouldBlock => break,
                            Err(_) => break 'conn,
                        }
                    }
                    if streaming && Instant::now() >= next {
                        next += Duration::from_micros(500);
                        out.extend(script.telemetry(n));
                        n += 1;
                    }
                    if !out.is_empty() && conn.write_all(&out).is_err() {
                        break;
                    }
                    std::thread::sleep(Duration::from_micros(200));
                }
            }
        });
        Self { port, stop, thread: Some(thread) }
    }
}
