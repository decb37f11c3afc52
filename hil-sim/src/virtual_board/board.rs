//! The virtual board's state between samples: what the firmware's tasks and interrupts hold.

use std::io::Write;

use firmware::link::{LinkAction, LinkWatch};
use firmware::runner::Loop;
use firmware::slots::{self, Slot, SlotState};
use model_core::control::{ConfigImage, PageError, ValidatedConfig};
use model_core::protocol::device::{Action, Device, StatusFigures};
use model_core::protocol::frame::{encode, MAX_ENCODED};
use model_core::protocol::telemetry::Telemetry;
use model_core::protocol::{mode_code, Nack, Response, FRAME};

use crate::closed_loop::rig::{Command, Rig, Sampled};
use crate::closed_loop::Schedule;
use crate::sim::plant::ClutchParams;

/// Where the virtual board writes what it applied and when (sample index first): `ref V`,
/// `enable 0|1`, `reset`, `page CRC` (a committed page swapped in before that sample). With
/// the scenario this reproduces the run exactly.
pub type Journal = Option<Box<dyn Write + Send>>;

/// The board's flash: the two configuration slots.
struct Flash {
    a: [u8; slots::SLOT_BYTES],
    b: [u8; slots::SLOT_BYTES],
}

/// The virtual board.
pub struct VirtualBoard {
    device: Device,
    link: LinkWatch,
    rig: Rig,
    lp: Loop,
    cfg: ValidatedConfig,
    pending: Option<(Loop, ValidatedConfig, u32)>,
    flash: Flash,
    running: Option<(Slot, u32)>,
    cmd: Command,
    reset_due: bool,
    overruns: u32,
    last: Option<Sampled>,
    journal: Journal,
    dt: f64,
}

fn runnable(img: &ConfigImage) -> Result<(Loop, ValidatedConfig), PageError> {
    firmware::bringup::check_board(&img.control, firmware::bringup::PWM_COUNTS)
        .map_err(|_| PageError::Malformed("settings for another board"))?;
    Loop::from_image(img).map(|lp| (lp, img.control))
}

impl VirtualBoard {
    /// A board with blank slots (the compiled-in defaults) against `clutch`.
    pub fn new(clutch: &ClutchParams, seed: u64, fault: Option<Schedule>, journal: Journal) -> Result<Self, PageError> {
        let img = firmware::bringup::default_image()?;
        let (lp, cfg) = runnable(&img)?;
        Ok(Self {
            device: Device::default(),
            link: LinkWatch::new(firmware::link::COMMAND_TIMEOUT_MS, 0),
            rig: Rig::new(clutch, &cfg, seed, fault),
            lp,
            cfg,
            pending: None,
            flash: Flash { a: [0xFF; slots::SLOT_BYTES], b: [0xFF; slots::SLOT_BYTES] },
            running: None,
            cmd: Command { reference: 0.0, enable: false, reset: false },
            reset_due: false,
            overruns: 0,
            last: None,
            journal,
            dt: f64::from(cfg.get().dt),
        })
    }

    /// Samples run.
    pub fn samples(&self) -> usize {
        self.rig.samples()
    }

    /// The control rate, Hz.
    pub fn control_hz(&self) -> f64 {
        1.0 / self.dt
    }

    fn now_ms(&self) -> u64 {
        (self.rig.samples() as f64 * self.dt * 1e3) as u64
    }

    fn log(&mut self, what: std::fmt::Arguments) {
        let k = self.rig.samples();
        if let Some(j) = self.journal.as_mut() {
            let _ = writeln!(j, "{k} {what}");
            let _ = j.flush();
        }
    }

    /// One frame from the host: the encoded replies to send.
    pub fn frame(&mut self, payload: &[u8]) -> Vec<u8> {
        if model_core::protocol::Command::decode(payload).is_ok() {
            self.link.heard(self.now_ms());
        }
        let reply = match self.device.handle(payload) {
            (Action::None, r) => r,
            (Action::Reference(t), r) => {
                self.cmd.reference = f64::from(t);
                self.log(format_args!("ref {t}"));
                r
            }
            (Action::Enable(e), r) => {
                self.cmd.enable = e;
                self.log(format_args!("enable {}", u8::from(e)));
                r
            }
            (Action::Reset, r) => {
                self.reset_due = true;
                r
            }
            (Action::Status, _) => Some(self.status()),
            (Action::Commit, _) => {
                let result = match self.device.take_page() {
                    Some(img) => {
                        let bytes = *self.device.page_bytes();
                        self.commit(&bytes, &img)
                    }
                    None => Err(Nack::Sequence),
                };
                Some(self.device.committed(result))
            }
        };
        reply.map(frame_bytes).unwrap_or_default()
    }

    fn status(&self) -> Response {
        let o = self.last.map(|s| s.out).unwrap_or_default();
        self.device.status(StatusFigures {
            mode: mode_code(o.mode),
            fault: o.fault.code(),
            overruns: self.overruns,
            torque_est: o.torque_est,
        })
    }

    /// The firmware's commit: validate against the board, write the slot not running
    /// (image, then the commit record), read it back, hand it to the control loop.
    fn commit(&mut self, bytes: &[u8; model_core::control::page::PAGE_BYTES], img: &ConfigImage) -> Result<(), Nack> {
        if self.cmd.enable {
            return Err(Nack::Busy);
        }
        let (lp, cfg) = runnable(img).map_err(|_| Nack::InvalidPage)?;
        let (slot, seq) = slots::commit_target(self.running);
        let image = slots::slot_image(bytes, seq).ok_or(Nack::InvalidPage)?;
        let dst = match slot {
            Slot::A => &mut self.flash.a,
            Slot::B => &mut self.flash.b,
        };
        *dst = image;
        let back = ConfigImage::decode(dst.get(..slots::IMAGE_BYTES).unwrap_or(&[])).map_err(|_| Nack::Flash)?;
        if slots::record_of(dst) != slots::Record::Committed(seq) || back.crc() != img.crc() {
            return Err(Nack::Flash);
        }
        self.running = Some((slot, seq));
        self.pending = Some((lp, cfg, img.crc()));
        self.device.set_active_crc(img.crc());
        Ok(())
    }

    /// What the slots hold (as the firmware reports them at start-up).
    pub fn slot_states(&self) -> (SlotState, SlotState) {
        let state = |s: &[u8; slots::SLOT_BYTES]| match slots::record_of(s) {
            slots::Record::Committed(seq) => SlotState::Valid(seq),
            _ if slots::is_blank(s) => SlotState::Blank,
            _ => SlotState::Unusable("no commit record"),
        };
        (state(&self.flash.a), state(&self.flash.b))
    }

    /// Run one control sample; the encoded telemetry frame when one is due.
    pub fn sample(&mut self) -> Option<Vec<u8>> {
        if self.link.poll(self.now_ms(), self.cmd.enable) == LinkAction::Release {
            self.cmd.enable = false;
            self.cmd.reference = 0.0;
            self.device.released();
            self.log(format_args!("release"));
        }
        // A committed page is swapped in only while the bridge is off.
        if !self.last.is_some_and(|s| s.applied.1) {
            if let Some((lp, cfg, crc)) = self.pending.take() {
                self.lp = lp;
                self.cfg = cfg;
                self.log(format_args!("page {crc:#010x}"));
            }
        }
        let reset = std::mem::take(&mut self.reset_due);
        if reset {
            self.log(format_args!("reset"));
        }
        let s = self.rig.sample(&mut self.lp, &mut self.cfg, Command { reset, ..self.cmd });
        self.last = Some(s);
        if !self.device.telemetry_due() {
            return None;
        }
        let o = s.out;
        let t = Telemetry {
            t_us: (s.t * 1e6).round() as u64 as u32,
            b: o.b,
            current: o.current,
            torque_est: o.torque_est,
            reference: self.cmd.reference as f32,
            duty: o.duty,
            mode: mode_code(o.mode),
            fault: o.fault.code(),
            torque_true: s.torque_true as f32,
        };
        let seq = self.device.next_seq();
        Some(encode_payload(&t.encode(seq)))
    }
}

fn encode_payload(p: &[u8]) -> Vec<u8> {
    let mut out = [0u8; MAX_ENCODED];
    let n = encode(p, &mut out);
    out[..n].to_vec()
}

fn frame_bytes(r: Response) -> Vec<u8> {
    let mut f = [0u8; FRAME];
    let n = r.encode(&mut f);
    encode_payload(&f[..n])
}
