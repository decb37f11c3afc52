//! Commands out, replies and telemetry in: frames on the byte stream
//! (`model_core::protocol::frame`), replies matched to their command, a timeout per
//! request, lost telemetry frames counted from the sequence numbers.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use model_core::protocol::frame::{encode, Deframer, MAX_ENCODED};
use model_core::protocol::telemetry::{self, lost_between, Telemetry};
use model_core::protocol::{Command, Nack, Response, FRAME};
use serde::Serialize;

use super::error::LinkError;
use super::port::Stream;

/// How long a reply may take (a commit writes flash: longer).
pub const REPLY: Duration = Duration::from_millis(500);
pub const COMMIT_REPLY: Duration = Duration::from_millis(3000);
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
    pub telemetry_lost: u64,
}

/// The board's status reply.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Status {
    pub mode: u8,
    pub fault: u8,
    pub overruns: u8,
    pub torque_estimate: f32,
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
}

fn why(n: Nack) -> &'static str {
    match n {
        Nack::Unknown => "unknown command (firmware older than this hil-sim?)",
        Nack::Malformed => "malformed frame",
        Nack::Sequence => "configuration data out of sequence (a frame was lost; load again)",
        Nack::TransferCrc => "the transferred page does not match its CRC (bytes lost on the line; load again)",
        Nack::InvalidPage => {
            "the page does not validate on the board (model not built in, or settings for another board)"
        }
        Nack::Busy => "not while the bridge is enabled (disable first)",
        Nack::Flash => "writing the flash page failed",
    }
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

    /// Send one command.
    pub fn send(&mut self, cmd: Command) -> Result<(), LinkError> {
        let mut f = [0u8; FRAME];
        let n = cmd.encode(&mut f);
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
    /// is queued.
    fn pump(&mut self, replies: &mut Vec<Response>) -> Result<bool, LinkError> {
        let mut buf = [0u8; 4096];
        let n = match self.io.read(&mut buf) {
            Ok(0) => return Err(self.io_err(std::io::ErrorKind::UnexpectedEof.into())),
            Ok(n) => n,
            Err(e) if matches!(e.kind(), std::io::ErrorKind::TimedOut | std::io::ErrorKind::WouldBlock) => {
                return Ok(false)
            }
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => return Ok(false),
            Err(e) => return Err(self.io_err(e)),
        };
        let mut any = false;
        for &b in &buf[..n] {
            let Some(r) = self.deframer.push(b) else { continue };
            match r {
                Err(_) => {
                    self.stats.crc_errors += 1;
                    self.crc_run += 1;
                }
                Ok(p) => {
                    any = true;
                    self.crc_run = 0;
                    self.stats.frames += 1;
                    if p.first() == Some(&telemetry::CODE) {
                        if let Some((seq, t)) = Telemetry::decode(p) {
                            if let Some(prev) = self.last_seq {
                                self.stats.telemetry_lost += u64::from(lost_between(prev, seq));
                            }
                            self.last_seq = Some(seq);
                            self.stats.telemetry_frames += 1;
                            self.telemetry.push_back(t);
                        }
                    } else if let Some(r) = Response::decode(p) {
                        replies.push(r);
                    }
                }
            }
        }
        Ok(any)
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

    /// Send `cmd` and wait for its reply (resent on a timeout, up to three times).
    pub fn request(&mut self, cmd: Command, what: &'static str, wait: Duration) -> Result<Response, LinkError> {
        let code = cmd.code();
        let accept = move |r: &Response| match r {
            Response::Ack(c) | Response::Nack(c, _) => *c == code,
            Response::Status { .. } => code == 0x04,
            Response::PageCrc(_) => code == 0x13,
        };
        for _ in 0..ATTEMPTS {
            self.send(cmd)?;
            if let Some(r) = self.reply(what, wait, &accept)? {
                return match r {
                    Response::Nack(_, n) => Err(LinkError::Refused { port: self.port.clone(), what, why: why(n) }),
                    r => Ok(r),
                };
            }
        }
        Err(LinkError::Timeout { port: self.port.clone(), what, ms: wait.as_millis() as u64 * u64::from(ATTEMPTS) })
    }

    /// A command answered by an ack.
    pub fn ack(&mut self, cmd: Command, what: &'static str) -> Result<(), LinkError> {
        match self.request(cmd, what, REPLY)? {
            Response::Ack(_) => Ok(()),
            r => Err(LinkError::Unexpected { port: self.port.clone(), what, reply: format!("{r:?}") }),
        }
    }

    /// The board's status.
    pub fn status(&mut self) -> Result<Status, LinkError> {
        match self.request(Command::GetStatus, "a status request", REPLY)? {
            Response::Status { mode, fault, overruns, torque_est } => {
                Ok(Status { mode, fault, overruns, torque_estimate: torque_est })
            }
            r => Err(LinkError::Unexpected {
                port: self.port.clone(),
                what: "a status request",
                reply: format!("{r:?}"),
            }),
        }
    }

    /// Telemetry received so far (waits up to one poll period for more); an error when
    /// nothing at all arrived for `silent`.
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

    /// Start (decimation ≥ 1) or stop (0) the telemetry stream.
    pub fn stream(&mut self, decimation: u16) -> Result<(), LinkError> {
        self.last_seq = None;
        self.ack(Command::Telemetry { decimation }, "the telemetry request")
    }
}
