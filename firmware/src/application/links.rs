//! What the two command links share, and one frame's way through the command handler
//! (`model_core::protocol::device::Device`): the action done, the reply returned. The
//! board's session (`model_core::protocol::session`) is here, one for both links: one host
//! controls the clutch, over whichever link it claimed.

use core::cell::Cell;
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use critical_section::Mutex;
use model_core::control::{FaultCode, LoopMode, Mode, ValidatedConfig};
use model_core::protocol::device::{Action, Device, Reply};
use model_core::protocol::session::Ended;
use model_core::protocol::{mode_code, Nack, Response, Sessions};

use super::ports::{Clock, ControlPort, Event, Events, FlashPages};
use super::time::after;
use super::{store, App};
use crate::link::{LinkAction, LinkWatch, COMMAND_TIMEOUT_MS};
use crate::slots::Slot;

/// State of both links together.
pub struct Shared {
    /// The command timeout of both links together ([`crate::link`]).
    link: Mutex<Cell<LinkWatch>>,
    /// The configuration running (slot, commit sequence); `None`: compiled-in defaults.
    running: Mutex<Cell<Option<(Slot, u32)>>>,
    /// A commit is being written (the other link's commit is refused meanwhile).
    committing: AtomicBool,
    /// Started with no usable configuration (the loop is held in a fault until a commit).
    pub(crate) damaged: AtomicBool,
    /// CRC-32 of the page running (0: the compiled-in defaults): what both links' page-CRC
    /// query answers, from start-up on and after a commit over either link.
    active_crc: AtomicU32,
    /// Who controls the clutch.
    sessions: Mutex<Cell<Sessions>>,
    /// The running page's reference limit (f32 bits; N·m, A in current mode), control rate
    /// (Hz) and confirmation count of its fast checks (samples).
    reference_max: AtomicU32,
    control_hz: AtomicU32,
    confirm: AtomicU32,
}

impl Shared {
    /// At start-up: the configuration [`store::load`] found, and its page's CRC-32.
    pub const fn new(running: Option<(Slot, u32)>, damaged: bool, crc: u32) -> Self {
        Self {
            link: Mutex::new(Cell::new(LinkWatch::new(COMMAND_TIMEOUT_MS, 0))),
            running: Mutex::new(Cell::new(running)),
            committing: AtomicBool::new(false),
            damaged: AtomicBool::new(damaged),
            active_crc: AtomicU32::new(crc),
            sessions: Mutex::new(Cell::new(Sessions::new())),
            reference_max: AtomicU32::new(0),
            control_hz: AtomicU32::new(0),
            confirm: AtomicU32::new(0),
        }
    }

    /// The limits of the page that runs from now on (at start-up, and after a commit: a
    /// page is committed only with the bridge off, and swapped in at the next sample).
    pub fn set_limits(&self, cfg: &ValidatedConfig, control_hz: u32) {
        let c = cfg.get();
        let max = if c.mode == LoopMode::Current { c.i_max } else { c.torque_max };
        self.reference_max.store(max.to_bits(), Ordering::Relaxed);
        self.control_hz.store(control_hz, Ordering::Relaxed);
        self.confirm.store(c.confirm_samples as u32, Ordering::Relaxed);
    }

    /// The running page's reference limit (N·m; A in current mode).
    pub fn reference_max(&self) -> f32 {
        f32::from_bits(self.reference_max.load(Ordering::Relaxed))
    }

    fn sessions<R>(&self, f: impl FnOnce(&mut Sessions) -> R) -> R {
        critical_section::with(|cs| {
            let cell = self.sessions.borrow(cs);
            let mut s = cell.get();
            let r = f(&mut s);
            cell.set(s);
            r
        })
    }

    /// Set the start-up configuration (a `static` made before loading it).
    pub fn booted(&self, running: Option<(Slot, u32)>, damaged: bool, crc: u32) {
        critical_section::with(|cs| self.running.borrow(cs).set(running));
        self.damaged.store(damaged, Ordering::Relaxed);
        self.active_crc.store(crc, Ordering::Relaxed);
    }

    /// CRC-32 of the page running (0: the compiled-in defaults).
    pub fn active_crc(&self) -> u32 {
        self.active_crc.load(Ordering::Relaxed)
    }

    pub fn running(&self) -> Option<(Slot, u32)> {
        critical_section::with(|cs| self.running.borrow(cs).get())
    }

    fn heard(&self, now_ms: u64) {
        critical_section::with(|cs| {
            let mut l = self.link.borrow(cs).get();
            l.heard(now_ms);
            self.link.borrow(cs).set(l);
        });
    }

    fn poll(&self, now_ms: u64, enabled: bool) -> LinkAction {
        critical_section::with(|cs| {
            let mut l = self.link.borrow(cs).get();
            let a = l.poll(now_ms, enabled);
            self.link.borrow(cs).set(l);
            a
        })
    }
}

fn now_ms(clock: &impl Clock) -> u64 {
    clock.now_us() / 1000
}

/// Drive off, reference zero (the event logged when a drive was released).
fn release<C, F, P: ControlPort, E: Events>(app: App<'_, C, F, P, E>) {
    let driven = app.ctl.enabled();
    app.ctl.set_enable(false);
    app.ctl.set_reference(0.0);
    if driven {
        app.events.event(Event::Released);
    }
}

/// Release the drive when its session's holder has not been heard for
/// `COMMAND_TIMEOUT_MS`, and end a session silent for its idle time (called on every
/// wake-up of a link task).
pub fn watch_link<C: Clock, F, P: ControlPort, E: Events>(app: App<'_, C, F, P, E>, device: &mut Device) {
    let now = now_ms(app.clock);
    let ended = app.shared.sessions(|s| s.expire(now));
    if app.shared.poll(now, app.ctl.enabled()) == LinkAction::Release || (ended == Ended::Yes && app.ctl.enabled()) {
        release(app);
    }
    if !app.ctl.enabled() {
        device.released();
    }
}

/// A reset, answered once the control step has taken it and the fast checks have had
/// their confirmation count of samples to latch a fault that is still there.
async fn reset<C: Clock, F, P: ControlPort, E>(app: App<'_, C, F, P, E>, reply: Reply) -> Response {
    app.ctl.request_reset();
    let settle = app.shared.confirm.load(Ordering::Relaxed).saturating_add(2);
    let start = app.ctl.samples();
    // At most 50 ms: the slowest control rate with the largest count stays far inside.
    for _ in 0..250 {
        if app.ctl.samples().wrapping_sub(start) >= settle {
            break;
        }
        after(app.clock, 200).await;
    }
    if faulted(app) {
        reply.nack(Nack::FaultPresent)
    } else {
        reply.ack()
    }
}

/// A fault is latched (as the last sample's status reads).
fn faulted<C, F, P: ControlPort, E>(app: App<'_, C, F, P, E>) -> bool {
    let st = app.ctl.status();
    st.fault != 0 || st.mode == FAULT_MODE
}

/// The status byte of the fault mode.
const FAULT_MODE: u8 = mode_code(Mode::Fault(FaultCode::None));

/// An enable, refused while a fault is latched (a reset must clear it first).
fn enable<C, F, P: ControlPort, E>(app: App<'_, C, F, P, E>, device: &mut Device, on: bool, reply: Reply) -> Response {
    if on && faulted(app) {
        device.released();
        return reply.nack(Nack::Faulted);
    }
    app.ctl.set_enable(on);
    reply.ack()
}

/// A reference within the running page's limit is applied; beyond it, refused (the
/// streamed form is answered only then).
fn reference<C, F, P: ControlPort, E>(app: App<'_, C, F, P, E>, value: f32, reply: Option<Reply>) -> Option<Response> {
    let max = app.shared.reference_max();
    if value.is_nan() || model_core::math::abs(value) > max {
        return reply.map(|r| r.nack(Nack::OutOfRange));
    }
    app.ctl.set_reference(value);
    reply.map(Reply::ack)
}

/// One frame from a link through the command handler: its action done, its reply returned.
pub async fn serve<C: Clock, F: FlashPages, P: ControlPort, E: Events>(
    app: App<'_, C, F, P, E>,
    device: &mut Device,
    data: &[u8],
) -> Option<Response> {
    let now = now_ms(app.clock);
    // The running page's CRC, whichever link committed it (or the slot it booted from).
    device.set_active_crc(app.shared.active_crc());
    let h = app.shared.sessions(|s| device.handle(data, now, s));
    if h.heard {
        app.shared.heard(now);
    }
    match h.action {
        Action::None => h.reply,
        Action::Reference { value, reply } => reference(app, value, reply),
        Action::Enable { on, reply } => Some(enable(app, device, on, reply)),
        Action::Reset { reply } => Some(reset(app, reply).await),
        Action::Released { reply } => {
            release(app);
            Some(reply.ack())
        }
        Action::Status => Some(device.status(app.ctl.status())),
        Action::Limits => Some(Response::Limits {
            reference_max: app.shared.reference_max(),
            control_hz: u16::try_from(app.shared.control_hz.load(Ordering::Relaxed)).unwrap_or(u16::MAX),
        }),
        Action::Commit => {
            let result = match (device.take_page(), app.shared.committing.swap(true, Ordering::Acquire)) {
                (_, true) => Err(Nack::Busy),
                (None, false) => Err(Nack::Sequence),
                (Some(img), false) => {
                    let r = store::commit(app, device.page_bytes(), &img, app.shared.running()).await;
                    app.shared.committing.store(false, Ordering::Release);
                    r.map(|now| (now, img))
                }
            };
            if let Ok((running, img)) = &result {
                critical_section::with(|cs| app.shared.running.borrow(cs).set(Some(*running)));
                app.shared.active_crc.store(img.crc(), Ordering::Relaxed);
                let hz = crate::runner::control_hz_of(img.model_id()).unwrap_or(0);
                app.shared.set_limits(&img.control, hz);
                device.set_active_crc(img.crc());
            }
            Some(device.committed(result.map(|_| ()), now_ms(app.clock)))
        }
    }
}
