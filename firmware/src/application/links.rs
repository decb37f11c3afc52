//! What the two command links share, and one frame's way through the command handler
//! (`model_core::protocol::device::Device`): the action done, the reply returned.

use core::cell::Cell;
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use critical_section::Mutex;
use model_core::protocol::device::{Action, Device};
use model_core::protocol::{Command, Nack, Response};

use super::ports::{Clock, ControlPort, Event, Events, FlashPages};
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
        }
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

/// Release the drive when no link has been heard for `COMMAND_TIMEOUT_MS` (called on every
/// wake-up of a link task).
pub fn watch_link<C: Clock, F, P: ControlPort, E: Events>(app: App<'_, C, F, P, E>, device: &mut Device) {
    if app.shared.poll(now_ms(app.clock), app.ctl.enabled()) == LinkAction::Release {
        app.ctl.set_enable(false);
        app.ctl.set_reference(0.0);
        app.events.event(Event::Released);
    }
    if !app.ctl.enabled() {
        device.released();
    }
}

/// One frame from a link through the command handler: its action done, its reply returned.
pub async fn serve<C: Clock, F: FlashPages, P: ControlPort, E: Events>(
    app: App<'_, C, F, P, E>,
    device: &mut Device,
    data: &[u8],
) -> Option<Response> {
    if Command::decode(data).is_ok() {
        app.shared.heard(now_ms(app.clock));
    }
    // The running page's CRC, whichever link committed it (or the slot it booted from).
    device.set_active_crc(app.shared.active_crc());
    match device.handle(data) {
        (Action::None, r) => r,
        (Action::Reference(t), r) => {
            app.ctl.set_reference(t);
            r
        }
        (Action::Enable(e), r) => {
            app.ctl.set_enable(e);
            r
        }
        (Action::Reset, r) => {
            app.ctl.request_reset();
            r
        }
        (Action::Status, _) => Some(device.status(app.ctl.status())),
        (Action::Commit, _) => {
            let result = match (device.take_page(), app.shared.committing.swap(true, Ordering::Acquire)) {
                (_, true) => Err(Nack::Busy),
                (None, false) => Err(Nack::Sequence),
                (Some(img), false) => {
                    let r = store::commit(app, device.page_bytes(), &img, app.shared.running()).await;
                    app.shared.committing.store(false, Ordering::Release);
                    r.map(|now| (now, img.crc()))
                }
            };
            if let Ok((now, crc)) = result {
                critical_section::with(|cs| app.shared.running.borrow(cs).set(Some(now)));
                app.shared.active_crc.store(crc, Ordering::Relaxed);
                device.set_active_crc(crc);
            }
            Some(device.committed(result.map(|_| ())))
        }
    }
}
