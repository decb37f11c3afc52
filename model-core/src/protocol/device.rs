//! The board's command handling as pure code, shared by the firmware's link tasks and
//! `hil-sim virtual-board`: a frame in, an [`Action`] for the application and the reply
//! out; the session and guard checks ([`super::session`]) made here, the configuration
//! page assembled here, telemetry decimated and numbered here. Committing a page (flash)
//! is the caller's: [`Action::Commit`] hands it the checked page.

use super::session::{clock16, Sessions};
use super::{Command, Nack, PageAssembler, Response};
use crate::control::page::{ConfigImage, PAGE_BYTES};

/// Whom a reply answers: the command byte, its guard's tag (0 unguarded), the board's
/// clock when it was handled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Reply {
    pub code: u8,
    pub tag: u16,
    pub now_ms: u16,
}

impl Reply {
    pub const fn ack(self) -> Response {
        Response::Ack { code: self.code, tag: self.tag, now_ms: self.now_ms }
    }
    pub const fn nack(self, why: Nack) -> Response {
        Response::Nack { code: self.code, why, tag: self.tag, now_ms: self.now_ms }
    }
    pub const fn result(self, r: Result<(), Nack>) -> Response {
        match r {
            Ok(()) => self.ack(),
            Err(why) => self.nack(why),
        }
    }
}

/// What the application must do for a frame. Where a [`Reply`] is given, the reply is the
/// application's to send once it has done (or refused) the action.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Action {
    /// Nothing beyond the reply.
    None,
    /// New torque reference, N·m (A in current mode); `reply` for the acknowledged form.
    Reference { value: f32, reply: Option<Reply> },
    /// Bridge on/off.
    Enable { on: bool, reply: Reply },
    /// Clear a latched fault.
    Reset { reply: Reply },
    /// Answer with [`Device::status`] (the application fills in its figures).
    Status,
    /// Answer with the running page's limits.
    Limits,
    /// Store this page (transfer CRC and decode already checked, bridge off), then answer
    /// with [`Device::committed`].
    Commit,
    /// The session ended (released by its holder): drive off, reference zero, then the reply.
    Released { reply: Reply },
}

/// A frame handled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Handled {
    pub action: Action,
    /// The reply to send at once (none when the action owes it, or for a streamed command).
    pub reply: Option<Response>,
    /// A guarded command of the session was admitted: its holder was heard (the drive's
    /// command timeout counts from here).
    pub heard: bool,
}

impl Handled {
    const fn reply(r: Response) -> Self {
        Self { action: Action::None, reply: Some(r), heard: false }
    }
    const fn act(action: Action) -> Self {
        Self { action, reply: None, heard: true }
    }
}

/// The figures a status reply carries.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StatusFigures {
    pub mode: u8,
    pub fault: u8,
    pub overruns: u32,
    pub torque_est: f32,
}

/// One link's command state.
#[derive(Clone, Debug, Default)]
pub struct Device {
    page: PageAssembler,
    /// The session whose guarded begin opened the transfer in `page`.
    transfer: Option<u8>,
    enabled: bool,
    pending: Option<ConfigImage>,
    /// Every `decimation`-th sample is streamed (0: off).
    decimation: u16,
    count: u16,
    seq: u16,
    /// CRC-32 of the running page (0: compiled-in defaults).
    active_crc: u32,
}

impl Device {
    /// A link's command state on a board that booted from a stored page: the page-CRC
    /// query answers `active_crc` from the first frame on, not 0 until a commit over this
    /// link. (The application keeps the running page's CRC where every link sees it and
    /// calls [`Device::set_active_crc`] with it; a commit over another link changes it.)
    pub fn with_active_crc(active_crc: u32) -> Self {
        Self { active_crc, ..Self::default() }
    }

    /// Handle one decoded frame's bytes at `now_ms` (the board's clock) with the board's
    /// `sessions`: the action, the reply when it is sent at once, whether the session's
    /// holder was heard.
    pub fn handle(&mut self, frame: &[u8], now_ms: u64, sessions: &mut Sessions) -> Handled {
        let code = frame.first().copied().unwrap_or(0);
        let now16 = clock16(now_ms);
        let cmd = match Command::decode(frame) {
            Ok(c) => c,
            Err(why) => return Handled::reply(Reply { code, tag: 0, now_ms: now16 }.nack(why)),
        };
        let r = Reply { code, tag: cmd.guard().map_or(0, |g| g.tag()), now_ms: now16 };
        if let Some(g) = cmd.guard() {
            if let Err(why) = sessions.admit(g, now_ms) {
                return Handled::reply(r.nack(why));
            }
        }
        match cmd {
            Command::SetTorque { reference, ack, .. } => {
                Handled::act(Action::Reference { value: reference, reply: ack.then_some(r) })
            }
            Command::Enable { on, .. } => {
                self.enabled = on;
                Handled::act(Action::Enable { on, reply: r })
            }
            Command::Reset { .. } => Handled::act(Action::Reset { reply: r }),
            Command::Heartbeat { .. } => Handled::act(Action::None),
            Command::Release { .. } => {
                let _ = sessions.release();
                self.released();
                Handled::act(Action::Released { reply: r })
            }
            Command::Claim { nonce } => Handled::reply(match sessions.claim(nonce, now_ms) {
                Ok(tag) => Response::Session { nonce, tag, now_ms: now16 },
                Err(why) => r.nack(why),
            }),
            Command::GetStatus => Handled { action: Action::Status, reply: None, heard: false },
            Command::Limits => Handled { action: Action::Limits, reply: None, heard: false },
            Command::ConfigQuery => Handled::reply(Response::PageCrc(self.active_crc)),
            Command::Telemetry { decimation } => {
                self.decimation = decimation;
                self.count = 0;
                Handled::reply(r.ack())
            }
            Command::ConfigBegin { guard, len } => {
                let begun = self.page.begin(len);
                self.transfer = begun.is_ok().then_some(guard.session);
                Handled { action: Action::None, reply: Some(r.result(begun)), heard: true }
            }
            Command::ConfigData { offset, len, data } => {
                let res = self.page.data(offset, data.get(..usize::from(len)).unwrap_or(&[]));
                Handled { action: Action::None, reply: res.err().map(|why| r.nack(why)), heard: false }
            }
            Command::ConfigCommit { crc } => match self.commit(crc, sessions) {
                Ok(()) => Handled { action: Action::Commit, reply: None, heard: false },
                Err(why) => Handled::reply(r.nack(why)),
            },
        }
    }

    /// A commit of the transfer: its session still held, the bridge off, the bytes whole.
    fn commit(&mut self, crc: u32, sessions: &Sessions) -> Result<(), Nack> {
        if self.transfer.is_none_or(|s| !sessions.holds(s)) {
            self.transfer = None;
            return Err(Nack::NoSession);
        }
        if self.enabled {
            return Err(Nack::Busy);
        }
        let (_, img) = self.page.commit(crc)?;
        self.pending = Some(img);
        Ok(())
    }

    /// The decoded page of the last [`Action::Commit`], until taken.
    pub fn take_page(&mut self) -> Option<ConfigImage> {
        self.pending.take()
    }

    /// The bytes of the page last transferred (what a commit writes to flash).
    pub fn page_bytes(&self) -> &[u8; PAGE_BYTES] {
        self.page.bytes()
    }

    /// The drive was released (the host fell silent): a commit is allowed again.
    pub fn released(&mut self) {
        self.enabled = false;
    }

    /// Record the running page's CRC-32 (at start-up, and after a commit was stored).
    pub fn set_active_crc(&mut self, crc: u32) {
        self.active_crc = crc;
    }

    /// The reply to a commit once the caller stored (or failed to store) the page.
    pub fn committed(&self, result: Result<(), Nack>, now_ms: u64) -> Response {
        Reply { code: 0x12, tag: 0, now_ms: clock16(now_ms) }.result(result)
    }

    /// The status reply.
    pub fn status(&self, s: StatusFigures) -> Response {
        Response::Status {
            mode: s.mode,
            fault: s.fault,
            overruns: u8::try_from(s.overruns).unwrap_or(u8::MAX),
            torque_est: s.torque_est,
        }
    }

    /// Every how many control samples telemetry is streamed (0: off).
    pub fn decimation(&self) -> u16 {
        self.decimation
    }

    /// Called once per control sample: true when this sample is to be streamed.
    pub fn telemetry_due(&mut self) -> bool {
        if self.decimation == 0 {
            return false;
        }
        self.count += 1;
        if self.count >= self.decimation {
            self.count = 0;
            return true;
        }
        false
    }

    /// The next telemetry sequence number.
    pub fn next_seq(&mut self) -> u16 {
        let s = self.seq;
        self.seq = self.seq.wrapping_add(1);
        s
    }
}
