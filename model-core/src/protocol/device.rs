//! The board's command handling as pure code, shared by the firmware's link tasks and
//! `hil-sim virtual-board`: a frame in, an [`Action`] for the application and the reply
//! out; the configuration page assembled here; telemetry decimated and numbered here.
//! Committing a page (flash) is the caller's: [`Action::Commit`] hands it the checked page.

use super::{Command, Nack, PageAssembler, Response};
use crate::control::page::{ConfigImage, PAGE_BYTES};

/// What the application must do for a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Action {
    /// Nothing beyond the reply.
    None,
    /// New torque reference, N·m.
    Reference(f32),
    /// Bridge on/off.
    Enable(bool),
    /// Clear a latched fault.
    Reset,
    /// Answer with [`Device::status`] (the application fills in its figures).
    Status,
    /// Store this page (transfer CRC and decode already checked, bridge off), then answer
    /// with [`Device::committed`].
    Commit,
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

    /// Handle one decoded frame's bytes: the action and, when the frame is answered at once,
    /// the reply.
    pub fn handle(&mut self, frame: &[u8]) -> (Action, Option<Response>) {
        let code = frame.first().copied().unwrap_or(0);
        let cmd = match Command::decode(frame) {
            Ok(c) => c,
            Err(why) => return (Action::None, Some(Response::Nack(code, why))),
        };
        let ack = Some(Response::Ack(code));
        match cmd {
            Command::SetTorque(t) => (Action::Reference(t), None),
            Command::Enable(e) => {
                self.enabled = e;
                (Action::Enable(e), ack)
            }
            Command::Reset => (Action::Reset, ack),
            Command::GetStatus => (Action::Status, None),
            Command::ConfigQuery => (Action::None, Some(Response::PageCrc(self.active_crc))),
            Command::Telemetry { decimation } => {
                self.decimation = decimation;
                self.count = 0;
                (Action::None, ack)
            }
            Command::ConfigBegin { len } => (Action::None, Some(reply(code, self.page.begin(len)))),
            Command::ConfigData { offset, len, data } => {
                let r = self.page.data(offset, data.get(..usize::from(len)).unwrap_or(&[]));
                (Action::None, r.err().map(|why| Response::Nack(code, why)))
            }
            Command::ConfigCommit { crc } => {
                if self.enabled {
                    return (Action::None, Some(Response::Nack(code, Nack::Busy)));
                }
                match self.page.commit(crc) {
                    Ok((_, img)) => {
                        self.pending = Some(img);
                        (Action::Commit, None)
                    }
                    Err(why) => (Action::None, Some(Response::Nack(code, why))),
                }
            }
        }
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
    pub fn committed(&self, result: Result<(), Nack>) -> Response {
        reply(0x12, result)
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

fn reply(code: u8, r: Result<(), Nack>) -> Response {
    match r {
        Ok(()) => Response::Ack(code),
        Err(why) => Response::Nack(code, why),
    }
}
