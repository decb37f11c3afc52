//! The configuration store: what a slot holds, which configuration boots, and a commit
//! (validate the page, check its model's physics, write it to the slot not running, read it
//! back, hand it to the control interrupt).
//!
//! The physics check ([`model_core::control::physics`]: the page's estimator on a slow
//! sweep of the field, refused when not finite, beyond the rating or not rising with the
//! field) runs in [`commit`] before flash is touched, in chunks with a yield between them
//! ([`physics_chunked`]); [`physics`] is the same check at once, for the host.
//!
//! Boot ([`load`], [`inspect`]) does not run it. A page in a slot was written by [`commit`],
//! which checked those very bytes (the page CRC keeps them), or flashed by a probe from
//! what `hil-sim export` wrote, which runs the same check; the check is a pure function of
//! the page, so at boot it could only repeat its answer. And it would cost: [`load`] runs
//! before the executor starts, synchronously, on both slots, so it would hold the first
//! control sample back by up to two sweeps (for Dahl at 20 kHz, 20 001 samples of about
//! 1 400 cycles, 0.17 s each, and about five times that at the 7 000-cycle bound of a step
//! with its slow pass) with nothing to yield to; and the read-back in [`commit`], which
//! goes through [`inspect`], would run it a second time.

use core::sync::atomic::Ordering;

use model_core::control::page::PAGE_BYTES;
use model_core::control::{ConfigImage, PageError, PhysicsFault, ValidatedConfig};
use model_core::protocol::Nack;

use super::ports::{Clock, ControlPort, Event, Events, FlashPages};
use super::time::yield_now;
use super::App;
use crate::bringup::{self, BoardMismatch};
use crate::runner::Loop;
use crate::slots::{self, Boot, Slot, SlotState};

/// A page error for the log (a name: formatting the numbers in it would pull core's float
/// formatting into the board's flash; `hil-sim export` gives the full message on the host).
pub fn page_error(e: &PageError) -> &'static str {
    match e {
        PageError::BadMagic => "blank or foreign page",
        PageError::UnsupportedVersion(_) => "unsupported format version",
        PageError::Malformed(what) => what,
        PageError::CrcMismatch { .. } => "CRC mismatch",
        PageError::Invalid(_) => "settings or model parameters out of range",
        PageError::WrongModel => "model not built into this firmware",
    }
}

/// Which configuration runs, as the debugger and the emulator read it: `seq << 2 | slot`
/// with slot 1 = A, 2 = B; 0 = compiled-in defaults on a blank board, 3 = defaults because
/// the slots are damaged.
pub fn source_code(running: Option<(Slot, u32)>, damaged: bool) -> u32 {
    match running {
        Some((Slot::A, seq)) => seq << 2 | 1,
        Some((Slot::B, seq)) => seq << 2 | 2,
        None if damaged => 3,
        None => 0,
    }
}

/// A decoded page as a controller, checked against the board (timer counts, period,
/// comparator range).
pub fn runnable(img: &ConfigImage) -> Result<(Loop, ValidatedConfig), PageError> {
    bringup::check_board(&img.control, bringup::PWM_COUNTS).map_err(|m| match m {
        BoardMismatch::PwmCounts => PageError::Malformed("pwm_counts is not the timer's"),
        BoardMismatch::SamplePeriod => PageError::Malformed("dt is not the control period"),
        BoardMismatch::OverCurrentRange => PageError::Malformed("over_current beyond the comparator"),
    })?;
    Loop::from_image(img).map(|lp| (lp, img.control))
}

/// Why a page is refused before it is written: it does not make a controller for this
/// board ([`runnable`]), or its model fails the physics check.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Refusal {
    Page(PageError),
    Physics(PhysicsFault),
}

/// Samples of the physics sweep between two yields to the other tasks. The costliest step
/// of a built-in model's estimator is below 7 000 cycles (the bound of a control step with
/// its slow pass, Dahl's and Hammerstein–Wiener's, `hil-sim budget`), so a chunk takes at
/// most 224 000 cycles: 1.3 ms at 170 MHz, 2.6 ms with the control interrupt's 50 % share,
/// well inside the watchdog task's 10 ms check and the 50 ms watchdog. A whole sweep is at
/// most 20 001 samples (626 chunks): for Dahl at its 1 358 cycles 0.16 s (0.32 s with the
/// interrupt's share), at the 7 000-cycle bound 0.8 s (1.6 s), within the 3 s the host
/// waits for a commit's reply.
pub const PHYSICS_CHUNK: u32 = 32;

/// The physics check of a page's model, the whole sweep at once: what the host refuses a
/// page with (`hil-sim export`, `board load`), the same code [`commit`] runs in chunks.
pub fn physics(img: &ConfigImage) -> Result<(), Refusal> {
    let (lp, cfg) = runnable(img).map_err(Refusal::Page)?;
    let mut sweep = lp.sweep(cfg.get());
    loop {
        if let Some(v) = sweep.advance(u32::MAX) {
            return v.map_err(Refusal::Physics);
        }
    }
}

/// [`physics`], [`PHYSICS_CHUNK`] samples at a time with a yield to the other tasks
/// between chunks (the watchdog task, the other link and the telemetry keep running).
pub async fn physics_chunked(img: &ConfigImage) -> Result<(), Refusal> {
    let (lp, cfg) = runnable(img).map_err(Refusal::Page)?;
    let mut sweep = lp.sweep(cfg.get());
    loop {
        if let Some(v) = sweep.advance(PHYSICS_CHUNK) {
            return v.map_err(Refusal::Physics);
        }
        yield_now().await;
    }
}

/// The reply to a page refused before it is written. The protocol has no reason for a
/// failed physics check yet: it is answered as an invalid page, like a page that does not
/// build; a dedicated `Nack` reason would be returned here for [`Refusal::Physics`].
fn refusal_nack(r: Refusal) -> Nack {
    match r {
        Refusal::Page(_) => Nack::InvalidPage,
        Refusal::Physics(_) => Nack::Physics,
    }
}

/// A usable slot's controller, its configuration and its page's CRC-32.
pub type Usable = (Loop, ValidatedConfig, u32);

/// What one slot holds, and its controller when it holds a usable page.
pub fn inspect(flash: &impl FlashPages, slot: Slot) -> (SlotState, Option<Usable>) {
    let Ok(bytes) = flash.read(slot) else {
        return (SlotState::Unusable("uncorrectable ECC error"), None);
    };
    if slots::is_blank(&bytes) {
        return (SlotState::Blank, None);
    }
    let seq = match slots::record_of(&bytes) {
        slots::Record::Committed(seq) => seq,
        slots::Record::Absent => 0,
        slots::Record::Broken => return (SlotState::Unusable("commit record cut (interrupted commit)"), None),
    };
    let image = bytes.get(..slots::IMAGE_BYTES).unwrap_or(&[]);
    match ConfigImage::decode(image).and_then(|img| runnable(&img).map(|(lp, cfg)| (lp, cfg, img.crc()))) {
        Ok(c) => (SlotState::Valid(seq), Some(c)),
        Err(e) => (SlotState::Unusable(page_error(&e)), None),
    }
}

/// The configuration that boots.
pub struct Loaded {
    pub lp: Loop,
    pub cfg: ValidatedConfig,
    /// The slot and commit it came from; `None`: the compiled-in defaults.
    pub running: Option<(Slot, u32)>,
    /// No slot held a usable page (the loop is held in a fault until a commit).
    pub damaged: bool,
    /// CRC-32 of the page it came from (0: the compiled-in defaults).
    pub crc: u32,
}

/// The newer valid slot, or the defaults (blank board), or the defaults with `damaged`
/// set. `Err`: the compiled-in configuration itself is refused (a build error).
pub fn load(flash: &impl FlashPages, events: &impl Events) -> Result<Loaded, PageError> {
    let (sa, ca) = inspect(flash, Slot::A);
    let (sb, cb) = inspect(flash, Slot::B);
    events.event(Event::Slots(sa, sb));
    let boot = slots::choose(sa, sb);
    let chosen = match boot {
        Boot::Slot(Slot::A, _) => ca,
        Boot::Slot(Slot::B, _) => cb,
        Boot::Blank | Boot::Damaged => None,
    };
    if let (Boot::Slot(slot, seq), Some((lp, cfg, crc))) = (boot, chosen) {
        events.event(Event::Loaded(slot, seq));
        return Ok(Loaded { lp, cfg, running: Some((slot, seq)), damaged: false, crc });
    }
    let damaged = boot == Boot::Damaged;
    events.event(if damaged { Event::Damaged } else { Event::Blank });
    let (lp, cfg) = bringup::default_image().and_then(|img| runnable(&img))?;
    Ok(Loaded { lp, cfg, running: None, damaged, crc: 0 })
}

/// Validate the received page and check its model's physics ([`physics_chunked`]), write
/// it to the slot not running (erase, image, commit record last; the flash waits yield),
/// read it back, hand the controller built from the read-back to the control interrupt.
/// The new (slot, commit).
pub async fn commit<C: Clock, F: FlashPages, P: ControlPort, E: Events>(
    app: App<'_, C, F, P, E>,
    bytes: &[u8; PAGE_BYTES],
    img: &ConfigImage,
    running: Option<(Slot, u32)>,
) -> Result<(Slot, u32), Nack> {
    if app.ctl.enabled() {
        return Err(Nack::Busy);
    }
    // Checked now, built again once written: a controller held across the flash waits
    // would sit in both link tasks' futures (11 KB each with every model built in). The
    // one the physics sweep runs on is dropped before them.
    physics_chunked(img).await.map_err(refusal_nack)?;
    let (slot, seq) = slots::commit_target(running);
    let image = slots::slot_image(bytes, seq).ok_or(Nack::InvalidPage)?;
    app.flash.program(slot, &image).await.map_err(|e| {
        app.events.event(Event::CommitFailed(slot, e));
        Nack::Flash
    })?;
    // The controller handed over is the one built from what the slot reads back.
    let (lp, cfg, crc) = match inspect(app.flash, slot) {
        (SlotState::Valid(s), Some(usable)) if s == seq => usable,
        (state, _) => {
            app.events.event(Event::ReadBack(slot, state));
            return Err(Nack::Flash);
        }
    };
    let model = lp.model_id();
    app.ctl.hand_over(lp, cfg, crc);
    // A board held by a damaged configuration runs again once a good page is committed.
    if app.shared.damaged.swap(false, Ordering::Relaxed) {
        app.ctl.request_reset();
    }
    app.ctl.running(Some((slot, seq)), false);
    app.events.event(Event::Committed(model, slot, seq));
    Ok((slot, seq))
}

#[cfg(test)]
mod tests {
    use core::cell::{Cell, RefCell};
    use core::future::Future;
    use core::pin::pin;
    use core::task::{Context, Poll, Waker};

    use model_core::protocol::device::StatusFigures;

    use super::*;
    use crate::application::ports::{EccError, FlashFault};
    use crate::application::{Shared, Snapshot, StreamSample};
    use crate::slots::SLOT_BYTES;

    /// Runs a future whose waits are all ready at once.
    fn block_on<F: Future>(f: F) -> F::Output {
        let mut f = pin!(f);
        loop {
            if let Poll::Ready(o) = f.as_mut().poll(&mut Context::from_waker(Waker::noop())) {
                return o;
            }
        }
    }

    struct Now;
    impl Clock for Now {
        fn now_us(&self) -> u64 {
            0
        }
        async fn at(&self, _: u64) {}
    }

    struct Pages(RefCell<[[u8; SLOT_BYTES]; 2]>);
    impl FlashPages for Pages {
        fn read(&self, slot: Slot) -> Result<[u8; SLOT_BYTES], EccError> {
            Ok(self.0.borrow()[slot as usize])
        }
        async fn program(&self, slot: Slot, image: &[u8; SLOT_BYTES]) -> Result<(), FlashFault> {
            self.0.borrow_mut()[slot as usize] = *image;
            Ok(())
        }
    }

    #[derive(Default)]
    struct Ctl {
        enabled: Cell<bool>,
        handed: Cell<Option<u32>>,
        source: Cell<u32>,
    }
    impl ControlPort for Ctl {
        fn set_reference(&self, _: f32) {}
        fn set_enable(&self, on: bool) {
            self.enabled.set(on);
        }
        fn enabled(&self) -> bool {
            self.enabled.get()
        }
        fn request_reset(&self) {}
        fn status(&self) -> StatusFigures {
            StatusFigures::default()
        }
        fn snapshot(&self) -> Snapshot {
            Snapshot::EMPTY
        }
        fn overruns(&self) -> u32 {
            0
        }
        fn samples(&self) -> u32 {
            0
        }
        fn stalled(&self) -> bool {
            false
        }
        fn stall(&self) {}
        fn request_slow_pass(&self) {}
        fn hand_over(&self, _: Loop, _: ValidatedConfig, crc: u32) {
            self.handed.set(Some(crc));
        }
        fn running(&self, running: Option<(Slot, u32)>, damaged: bool) {
            self.source.set(source_code(running, damaged));
        }
        fn set_stream_decimation(&self, _: u32) {}
        fn pop_stream(&self) -> Option<StreamSample> {
            None
        }
    }

    struct Quiet;
    impl Events for Quiet {
        fn event(&self, _: Event) {}
    }

    fn page() -> (ConfigImage, [u8; PAGE_BYTES]) {
        let img = bringup::default_image().expect("default page");
        let bytes = img.encode();
        (img, bytes)
    }

    #[test]
    fn a_commit_is_refused_while_driven_and_otherwise_boots_from_its_slot() {
        let flash = Pages(RefCell::new([[0xFF; SLOT_BYTES]; 2]));
        let (ctl, shared) = (Ctl::default(), Shared::new(None, false, 0));
        let app = App { clock: &Now, flash: &flash, ctl: &ctl, events: &Quiet, shared: &shared };
        let (img, bytes) = page();
        ctl.enabled.set(true);
        assert_eq!(block_on(commit(app, &bytes, &img, None)), Err(Nack::Busy));
        assert!(slots::is_blank(&flash.0.borrow()[0]), "nothing written while driven");
        ctl.enabled.set(false);
        let (slot, seq) = block_on(commit(app, &bytes, &img, None)).expect("commit");
        assert_eq!(ctl.handed.get(), Some(img.crc()), "the controller handed to the interrupt");
        assert_eq!(ctl.source.get(), source_code(Some((slot, seq)), false));
        let boot = load(&flash, &Quiet).expect("boot");
        assert_eq!(boot.running, Some((slot, seq)), "the next boot runs the committed slot");
        assert!(!boot.damaged);
        assert_eq!(boot.crc, img.crc(), "the page-CRC query answers the booted page's CRC");
        let blank = Pages(RefCell::new([[0xFF; SLOT_BYTES]; 2]));
        assert_eq!(load(&blank, &Quiet).expect("blank boot").crc, 0, "the compiled-in defaults answer 0");
        // The next commit goes to the other slot with a newer sequence.
        let (slot2, seq2) = block_on(commit(app, &bytes, &img, boot.running)).expect("second commit");
        assert_ne!(slot2, slot);
        assert!(slots::newer(seq, seq2), "commit {seq2} is newer than {seq}");
        assert_eq!(load(&flash, &Quiet).expect("boot").running, Some((slot2, seq2)));
    }

    /// The compiled-in page with its model's stiffness (the first parameter) negated.
    fn flipped() -> (ConfigImage, [u8; PAGE_BYTES]) {
        let d = bringup::default_image().expect("default page");
        let mut p = [0.0f32; 4];
        p.copy_from_slice(d.params());
        p[0] = -p[0];
        let img = ConfigImage::new(d.model_id(), &p, d.rate, d.control).expect("page");
        (img, img.encode())
    }

    #[test]
    fn a_page_whose_estimate_falls_with_the_field_is_refused_before_flash() {
        let flash = Pages(RefCell::new([[0xFF; SLOT_BYTES]; 2]));
        let (ctl, shared) = (Ctl::default(), Shared::new(None, false, 0));
        let app = App { clock: &Now, flash: &flash, ctl: &ctl, events: &Quiet, shared: &shared };
        let (img, bytes) = flipped();
        assert!(matches!(physics(&img), Err(Refusal::Physics(PhysicsFault::Decreasing { .. }))));
        assert!(matches!(block_on(physics_chunked(&img)), Err(Refusal::Physics(PhysicsFault::Decreasing { .. }))));
        assert_eq!(block_on(commit(app, &bytes, &img, None)), Err(Nack::Physics));
        assert!(flash.0.borrow().iter().all(|s| slots::is_blank(s)), "nothing written");
        assert_eq!(ctl.handed.get(), None, "nothing handed to the interrupt");
        // The compiled-in page passes, at once and in chunks, and still commits and boots.
        let (good, good_bytes) = page();
        assert_eq!(physics(&good), Ok(()));
        assert_eq!(block_on(physics_chunked(&good)), Ok(()));
        let (slot, seq) = block_on(commit(app, &good_bytes, &good, None)).expect("commit");
        assert_eq!(inspect(&flash, slot).0, SlotState::Valid(seq), "the stored page boots");
    }

    #[test]
    fn the_chunked_check_yields_between_chunks() {
        let (img, _) = page();
        let mut f = pin!(physics_chunked(&img));
        let mut polls = 0u32;
        while f.as_mut().poll(&mut Context::from_waker(Waker::noop())).is_pending() {
            polls += 1;
        }
        // 20 001 samples at 20 kHz in chunks of PHYSICS_CHUNK: one yield after each but the last.
        assert_eq!(polls, 20_001u32.div_ceil(PHYSICS_CHUNK) - 1);
    }
}
