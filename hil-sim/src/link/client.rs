//! Commands out, replies and telemetry in: frames on the byte stream
//! (`model_core::protocol::frame`), replies matched to their command by its code and guard
//! tag, a timeout per request, lost telemetry frames counted from the sequence numbers.
//!
//! A command that drives the clutch goes out in the link's session (claimed on first use,
//! released when the link is dropped) with a fresh sequence number and a deadline on the
//! board's clock, which the link follows from the clock every ack and nack carries. A
//! command that timed out is sent again under a new sequence number; the old one, should it
//! still arrive, is refused by the board as expired or overtaken. So when this link reports
//! that a command failed, the board did not run it (`model_core::protocol::session`).

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use model_core::control::FaultCode;
use model_core::protocol::frame::{encode, Deframer, MAX_ENCODED};
use model_core::protocol::mode_code;
use model_core::protocol::session::IDLE_MS;
use model_core::protocol::telemetry::{self, Telemetry};
use model_core::protocol::{Command, Guard, Nack, Response, FRAME};
use serde::Serialize;

use super::error::LinkError;
use super::port::Stream;

/// How long a reply may take (a commit writes flash: longer).
pub const REPLY: Duration = Duration::from_millis(500);
pub const COMMIT_REPLY: Duration = Duration::from_millis(3000);
/// How far ahead of the board's clock an acknowledged command's deadline lies: shorter
/// than [`REPLY`], so a command the host gave up on has expired on the board.
pub const LEAD: Duration = Duration::from_millis(300);
/// The deadline of a streamed command (a set-point or a heartbeat, sent every few ms):
/// one that arrives later than this is of no use any more.
pub const STREAM_LEAD: Duration = Duration::from_millis(100);
/// Attempts of a request whose frame or reply may be lost on the line.
const ATTEMPTS: u32 = 3;
/// CRC failures in a row that end a request.
const CRC_LIMIT: u32 = 64;

/// What the link saw.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct LinkStats {
    pub frames: u64,
    pub crc_errors: u64,
    pub telemetry_frames: u64,
    /// Frames missing between two received in sequence.
    pub telemetry_lost: u64,
    /// Frames whose sequence number did not move forward (duplicated or reordered on
    /// the line): not counted as lost, not recorded.
    pub telemetry_out_of_order: u64,
    /// Streamed commands the board refused, and the last reason.
    pub refused: u64,
    #[serde(skip)]
    pub last_refusal: Option<Nack>,
}

/// The board's status reply.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Status {
    pub mode: u8,
    pub fault: u8,
    pub overruns: u8,
    pub torque_estimate: f32,
}

/// The name of a status mode byte.
pub fn mode_name(code: u8) -> &'static str {
    use model_core::control::Mode::*;
    [Init, Calibrating, Running, Disabled, Fault(FaultCode::None)].into_iter().find(|m| mode_code(*m) == code).map_or(
        "unknown",
        |m| match m {
            Init => "init",
            Calibrating => "calibrating",
            Running => "running",
            Disabled => "disabled",
            Fault(_) => "fault",
        },
    )
}

/// The name of a fault code.
pub fn fault_name(code: u8) -> &'static str {
    FaultCode::ALL.iter().find(|f| f.code() == code).map_or("unknown", |f| f.name())
}

/// The running page's limits (the `limits` reply).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Limits {
    /// Largest |reference|, N·m (A in current mode).
    pub reference_max: f32,
    pub control_hz: u16,
}

/// The board's clock as the host follows it: its reading in the last reply and when that
/// reply arrived. The estimate lags the board by the reply's latency, which only moves the
/// deadlines written from it earlier.
#[derive(Clone, Copy, Debug)]
struct BoardClock {
    ms: u16,
    at: Instant,
}

impl BoardClock {
    fn now(&self) -> u16 {
        let elapsed = self.at.elapsed().as_millis() as u64;
        self.ms.wrapping_add(elapsed as u16)
    }
}

/// The session this link holds: the guard of the last command sent.
#[derive(Clone, Copy, Debug)]
struct Held {
    last: Guard,
}

/// An open link.
pub struct Link {
    io: Box<dyn Stream>,
    port: String,
    deframer: Deframer,
    pub stats: LinkStats,
    last_seq: Option<u16>,
    telemetry: VecDeque<Telemetry>,
    crc_run: u32,
    /// Telemetry frames are taken only once the stream request was acknowledged (frames
    /// of an earlier stream still on the line would count as a gap).
    streaming: bool,
    clock: Option<BoardClock>,
    session: Option<Held>,
    nonce: u16,
}

/// The reason of a refusal, as a user reads it.
pub fn why(n: Nack) -> &'static str {
    match n {
        Nack::Unknown => "unknown command (firmware older than this hil-sim?)",
        Nack::Malformed => "malformed frame",
        Nack::Sequence => "configuration data out of sequence (a frame was lost; load again)",
        Nack::TransferCrc => "the transferred page does not match its CRC (bytes lost on the line; load again)",
        Nack::InvalidPage => {
            "the page does not validate on the board (model not built in, or settings for another board)"
        }
        Nack::Busy => "not while the bridge is enabled, or while a commit is being written (disable first)",
        Nack::Flash => "writing the flash page failed",
        Nack::Expired => "it arrived after its deadline (the line or the host was too slow); it did not run",
        Nack::Stale => "its sequence number was not ahead of the last command run (a duplicate); it did not run",
        Nack::NoSession => "this host holds no session on the board (it ended: silence or another claim)",
        Nack::Held => "another host controls the board (wait until it releases, or its session times out)",
        Nack::Faulted => "a fault is latched (clear it with `board reset` first)",
        Nack::FaultPresent => "the fault is still present after the reset (it latched again)",
        Nack::OutOfRange => "the reference is beyond the running page's limit",
        Nack::Physics => "the page would drive the clutch wrongly (the board's physics check refused it)",
    }
}

/// The replies that answer a claim with `nonce`: its session, or the refusal.
fn answers_claim(nonce: u16) -> impl Fn(&Response) -> bool {
    move |r: &Response| match r {
        Response::Session { nonce: n, .. } => *n == nonce,
        Response::Nack { code: 0x06, .. } => true,
        _ => false,
    }
}

/// A nonce for a claim: different for every link the process opens.
fn nonce() -> u16 {
    use std::hash::{BuildHasher, Hasher};
    let mut h = std::collections::hash_map::RandomState::new().build_hasher();
    h.write_u128(Instant::now().elapsed().as_nanos() ^ u128::from(std::process::id()));
    (h.finish() as u16).max(1)
}

impl Link {
    pub fn new(io: Box<dyn Stream>, port: &str) -> Self {
        Self {
            io,
            port: port.to_owned(),
            deframer: Deframer::default(),
            stats: LinkStats::default(),
            last_seq: None,
            telemetry: VecDeque::new(),
            crc_run: 0,
            streaming: false,
            clock: None,
            session: None,
            nonce: nonce(),
        }
    }

    /// Open `port` ([`super::port::open`]).
    pub fn open(port: &str) -> Result<Self, LinkError> {
        Ok(Self::new(super::port::open(port)?, port))
    }

    pub fn port(&self) -> &str {
        &self.port
    }

    fn io_err(&self, source: std::io::Error) -> LinkError {
        LinkError::Io { port: self.port.clone(), source }
    }

    fn refused(&self, what: &'static str, n: Nack) -> LinkError {
        LinkError::Refused { port: self.port.clone(), what, why: why(n), reason: n }
    }

    /// Send one command (a set-torque reference no frame carries is refused here).
    pub fn send(&mut self, cmd: Command) -> Result<(), LinkError> {
        let mut f = [0u8; FRAME];
        let n = cmd.encode(&mut f);
        if n == 0 {
            return Err(LinkError::Unsendable { port: self.port.clone(), what: format!("{cmd:?}") });
        }
        let mut out = [0u8; MAX_ENCODED];
        let m = encode(f.get(..n).unwrap_or(&[]), &mut out);
        // A leading delimiter ends whatever garbage the receiver holds.
        let mut bytes = Vec::with_capacity(m + 1);
        bytes.push(0);
        bytes.extend_from_slice(&out[..m]);
        self.io.write_all(&bytes).map_err(|e| self.io_err(e))?;
        Ok(())
    }

    /// Read what is there (waits at most one poll period); replies are returned, telemetry
    /// is queued. Whether any telemetry frame arrived.
    fn pump(&mut self, replies: &mut Vec<Response>) -> Result<bool, LinkError> {
        let mut buf = [0u8; 4096];
        let n = match self.io.read(&mut buf) {
            Ok(0) => return Err(LinkError::Closed { port: self.port.clone() }),
            Ok(n) => n,
            Err(e) if matches!(e.kind(), std::io::ErrorKind::TimedOut | std::io::ErrorKind::WouldBlock) => {
                return Ok(false)
            }
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => return Ok(false),
            Err(e) => return Err(self.io_err(e)),
        };
        let mut streamed = false;
        for &b in &buf[..n] {
            let Some(r) = self.deframer.push(b) else { continue };
            match r {
                Err(_) => {
                    self.stats.crc_errors += 1;
                    self.crc_run += 1;
                }
                Ok(p) => {
                    self.crc_run = 0;
                    self.stats.frames += 1;
                    if p.first() == Some(&telemetry::CODE) {
                        if let Some((seq, t)) = Telemetry::decode(p) {
                            streamed |= self.take_telemetry(seq, t);
                        }
                    } else if let Some(r) = Response::decode(p) {
                        self.observe(&r);
                        replies.push(r);
                    }
                }
            }
        }
        Ok(streamed)
    }

    /// Queue a telemetry frame that moves the sequence forward; count the gap before it.
    fn take_telemetry(&mut self, seq: u16, t: Telemetry) -> bool {
        if !self.streaming {
            return false;
        }
        if let Some(prev) = self.last_seq {
            let ahead = seq.wrapping_sub(prev);
            // Forward by less than half the sequence space: in order (a gap is lost
            // frames); otherwise it went back: a duplicate or a reordered frame.
            if ahead == 0 || ahead >= 0x8000 {
                self.stats.telemetry_out_of_order += 1;
                return false;
            }
            self.stats.telemetry_lost += u64::from(ahead - 1);
        }
        self.last_seq = Some(seq);
        self.stats.telemetry_frames += 1;
        self.telemetry.push_back(t);
        true
    }

    /// What a reply tells beside its answer: the board's clock, a refused streamed command.
    fn observe(&mut self, r: &Response) {
        match *r {
            Response::Ack { now_ms, .. } | Response::Session { now_ms, .. } => {
                self.clock = Some(BoardClock { ms: now_ms, at: Instant::now() });
            }
            Response::Nack { now_ms, why, code, tag } => {
                self.clock = Some(BoardClock { ms: now_ms, at: Instant::now() });
                // On a shared line (the virtual board's other hosts) a nack may answer
                // another host's command: only this session's count.
                let ours = self.session.is_some_and(|h| Guard::from_tag(tag, 0).session == h.last.session);
                if ours && matches!(code, 0x01 | 0x08) {
                    self.stats.refused += 1;
                    self.stats.last_refusal = Some(why);
                }
                if ours && why == Nack::NoSession {
                    self.session = None;
                }
            }
            _ => {}
        }
    }

    /// Wait up to `wait` for a reply that `accept` takes.
    fn reply(
        &mut self,
        what: &'static str,
        wait: Duration,
        accept: &dyn Fn(&Response) -> bool,
    ) -> Result<Option<Response>, LinkError> {
        let end = Instant::now() + wait;
        let mut replies = Vec::new();
        while Instant::now() < end {
            self.pump(&mut replies)?;
            if let Some(r) = replies.drain(..).find(|r| accept(r)) {
                return Ok(Some(r));
            }
            if self.crc_run >= CRC_LIMIT {
                return Err(LinkError::Crc { port: self.port.clone(), what, n: self.crc_run });
            }
        }
        Ok(None)
    }

    /// Send an unguarded `cmd` and wait for its reply (sent again on a timeout, up to
    /// three times: these commands only read, or are idempotent).
    pub fn request(&mut self, cmd: Command, what: &'static str, wait: Duration) -> Result<Response, LinkError> {
        let code = cmd.code();
        let accept = move |r: &Response| match r {
            Response::Ack { code: c, tag: 0, .. } | Response::Nack { code: c, tag: 0, .. } => *c == code,
            Response::Status { .. } => code == 0x04,
            Response::PageCrc(_) => code == 0x13,
            Response::Limits { .. } => code == 0x14,
            _ => false,
        };
        for _ in 0..ATTEMPTS {
            self.send(cmd)?;
            if let Some(r) = self.reply(what, wait, &accept)? {
                return match r {
                    Response::Nack { why, .. } => Err(self.refused(what, why)),
                    r => Ok(r),
                };
            }
        }
        Err(self.timeout(what, wait))
    }

    /// [`Link::request`] sent once (for a command that must not be repeated).
    pub fn request_once(&mut self, cmd: Command, what: &'static str, wait: Duration) -> Result<Response, LinkError> {
        let code = cmd.code();
        self.send(cmd)?;
        let accept = move |r: &Response| matches!(r, Response::Ack { code: c, tag: 0, .. } | Response::Nack { code: c, tag: 0, .. } if *c == code);
        match self.reply(what, wait, &accept)? {
            Some(Response::Nack { why, .. }) => Err(self.refused(what, why)),
            Some(r) => Ok(r),
            None => Err(LinkError::Timeout { port: self.port.clone(), what, ms: wait.as_millis() as u64 }),
        }
    }

    fn timeout(&self, what: &'static str, wait: Duration) -> LinkError {
        LinkError::Timeout { port: self.port.clone(), what, ms: wait.as_millis() as u64 * u64::from(ATTEMPTS) }
    }

    /// Claim the board for this link (a no-op while the session is held). Another host's
    /// session is waited for until it would have timed out; then [`LinkError::Held`].
    pub fn claim(&mut self) -> Result<(), LinkError> {
        if self.session.is_some() {
            return Ok(());
        }
        let nonce = self.nonce;
        let accept = answers_claim(nonce);
        let give_up = Instant::now() + Duration::from_millis(IDLE_MS) + REPLY;
        let mut answered = false;
        loop {
            self.send(Command::Claim { nonce })?;
            match self.reply("the claim", REPLY, &accept)? {
                Some(Response::Session { tag, .. }) => {
                    // The tag names the first command: the "last" is the one before it.
                    let first = Guard::from_tag(tag, 0);
                    let last = Guard { seq: first.seq.wrapping_sub(1) & 0x0FFF, ..first };
                    self.session = Some(Held { last });
                    return Ok(());
                }
                Some(Response::Nack { why: Nack::Held, .. }) => answered = true,
                Some(Response::Nack { why, .. }) => return Err(self.refused("the claim", why)),
                _ => {}
            }
            if Instant::now() >= give_up {
                return Err(if answered {
                    LinkError::Held { port: self.port.clone(), ms: IDLE_MS }
                } else {
                    self.timeout("the claim", REPLY)
                });
            }
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    /// Read the board's clock again: a claim repeated with this link's nonce is answered
    /// with the session it holds and the clock. Over a long run without acks (a profile
    /// streamed for an hour) the host's estimate of the board's clock would drift with the
    /// two crystals; read again every second, it stays within a few ms.
    pub fn resync(&mut self) -> Result<(), LinkError> {
        let nonce = self.nonce;
        self.send(Command::Claim { nonce })?;
        let accept = answers_claim(nonce);
        match self.reply("the clock read", REPLY, &accept)? {
            Some(Response::Session { .. }) => Ok(()),
            Some(Response::Nack { why, .. }) => Err(self.refused("the clock read", why)),
            _ => Err(LinkError::Timeout {
                port: self.port.clone(),
                what: "the clock read",
                ms: REPLY.as_millis() as u64,
            }),
        }
    }

    /// The guard of the next command, its deadline `lead` ahead of the board's clock.
    fn next_guard(&mut self, lead: Duration) -> Result<Guard, LinkError> {
        self.claim()?;
        let now = self.clock.map_or(0, |c| c.now());
        let held = self.session.as_mut().ok_or_else(|| LinkError::Closed { port: self.port.clone() })?;
        let g = held.last.next(now.wrapping_add(lead.as_millis() as u16));
        held.last = g;
        Ok(g)
    }

    /// A guarded command answered by an ack: sent under a fresh sequence number and
    /// deadline on each attempt; `Ok` only when the board acknowledged it.
    pub fn command(&mut self, build: impl Fn(Guard) -> Command, what: &'static str) -> Result<(), LinkError> {
        self.command_waiting(build, what, REPLY)
    }

    /// [`Link::command`] with its own reply time (a reset waits for the fault checks).
    pub fn command_waiting(
        &mut self,
        build: impl Fn(Guard) -> Command,
        what: &'static str,
        wait: Duration,
    ) -> Result<(), LinkError> {
        for _ in 0..ATTEMPTS {
            let g = self.next_guard(LEAD.min(wait))?;
            let cmd = build(g);
            let (code, tag) = (cmd.code(), g.tag());
            self.send(cmd)?;
            let accept = move |r: &Response| match r {
                Response::Ack { code: c, tag: t, .. } | Response::Nack { code: c, tag: t, .. } => {
                    *c == code && *t == tag
                }
                _ => false,
            };
            match self.reply(what, wait, &accept)? {
                Some(Response::Ack { .. }) => return Ok(()),
                // Too late on the way: try again under a new deadline.
                Some(Response::Nack { why: Nack::Expired, .. }) => {}
                Some(Response::Nack { why: Nack::NoSession, .. }) => self.session = None,
                Some(Response::Nack { why, .. }) => return Err(self.refused(what, why)),
                _ => {}
            }
        }
        Err(LinkError::NotRun { port: self.port.clone(), what, ms: wait.as_millis() as u64 * u64::from(ATTEMPTS) })
    }

    /// A streamed guarded command (a set-point, a heartbeat): no ack; the board answers
    /// only a refusal, counted in [`LinkStats::refused`].
    pub fn stream_command(&mut self, build: impl Fn(Guard) -> Command) -> Result<(), LinkError> {
        let g = self.next_guard(STREAM_LEAD)?;
        self.send(build(g))
    }

    /// End this link's session (the board releases the drive); best effort when the board
    /// does not answer.
    pub fn release(&mut self) -> Result<(), LinkError> {
        if self.session.is_none() {
            return Ok(());
        }
        let r = self.command(|guard| Command::Release { guard }, "the release");
        self.session = None;
        r
    }

    /// An unguarded command answered by an ack (the telemetry request).
    pub fn ack(&mut self, cmd: Command, what: &'static str) -> Result<(), LinkError> {
        match self.request(cmd, what, REPLY)? {
            Response::Ack { .. } => Ok(()),
            r => Err(LinkError::Unexpected { port: self.port.clone(), what, reply: format!("{r:?}") }),
        }
    }

    /// The board's status.
    pub fn status(&mut self) -> Result<Status, LinkError> {
        match self.request(Command::GetStatus, "a status request", REPLY)? {
            Response::Status { mode, fault, overruns, torque_est } => {
                Ok(Status { mode, fault, overruns, torque_estimate: torque_est })
            }
            r => Err(self.unexpected("a status request", r)),
        }
    }

    /// The running page's limits.
    pub fn limits(&mut self) -> Result<Limits, LinkError> {
        match self.request(Command::Limits, "the limits query", REPLY)? {
            Response::Limits { reference_max, control_hz } => Ok(Limits { reference_max, control_hz }),
            r => Err(self.unexpected("the limits query", r)),
        }
    }

    /// The CRC-32 of the page that runs (0: the compiled-in defaults).
    pub fn page_crc(&mut self) -> Result<u32, LinkError> {
        match self.request(Command::ConfigQuery, "the page query", REPLY)? {
            Response::PageCrc(crc) => Ok(crc),
            r => Err(self.unexpected("the page query", r)),
        }
    }

    fn unexpected(&self, what: &'static str, r: Response) -> LinkError {
        LinkError::Unexpected { port: self.port.clone(), what, reply: format!("{r:?}") }
    }

    /// Telemetry received so far (waits up to one poll period for more); an error when no
    /// telemetry frame arrived for `silent` (replies do not count: a board that answers
    /// but does not stream is silent).
    pub fn telemetry(&mut self, silent: Duration, what: &'static str) -> Result<Vec<Telemetry>, LinkError> {
        let end = Instant::now() + silent;
        let mut replies = Vec::new();
        loop {
            let got = self.pump(&mut replies)?;
            if got || !self.telemetry.is_empty() {
                return Ok(self.telemetry.drain(..).collect());
            }
            if Instant::now() >= end {
                return Err(LinkError::Silent { port: self.port.clone(), what, ms: silent.as_millis() as u64 });
            }
        }
    }

    /// Start (decimation ≥ 1) or stop (0) the telemetry stream. Frames are taken from its
    /// acknowledgement on, numbered afresh.
    pub fn stream(&mut self, decimation: u16) -> Result<(), LinkError> {
        self.streaming = false;
        self.last_seq = None;
        self.telemetry.clear();
        self.ack(Command::Telemetry { decimation }, "the telemetry request")?;
        self.streaming = decimation != 0;
        Ok(())
    }
}

impl Drop for Link {
    /// A link that goes away releases its session, so the drive stops at once rather than
    /// after the board's command timeout.
    fn drop(&mut self) {
        if self.session.is_some() {
            if let Ok(g) = self.next_guard(LEAD) {
                let _ = self.send(Command::Release { guard: g });
            }
        }
    }
}
