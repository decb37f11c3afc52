//! The application's ports ([`firmware::application::ports`]) over this board's
//! peripherals: embassy-time for the clock, the flash slots by register ([`super::flash`]),
//! the control interrupt's atomics and cells ([`crate::controller`]), the IWDG, FDCAN1 and
//! defmt for the log. All zero-sized or thin wrappers: the application is monomorphised
//! over them (no dynamic dispatch anywhere).

use core::future::Future;
use core::sync::atomic::Ordering;

use defmt::{error, info, warn};
use embassy_stm32::peripherals::IWDG;
use embassy_stm32::wdg::IndependentWatchdog;
use embassy_time::{Instant, Timer};
use firmware::application::store::source_code;
use firmware::application::{
    BusError, CanFrame, CanPort, Clock, ControlPort, EccError, Event, Events, FlashFault, FlashPages, Snapshot,
    StreamSample, Watchdog,
};
use firmware::runner::Loop;
use firmware::slots::{Slot, SLOT_BYTES};
use model_core::control::ValidatedConfig;
use model_core::protocol::device::StatusFigures;
use model_core::protocol::mode_code;

use super::flash;
use crate::controller;

/// embassy-time (TIM15).
pub struct BoardClock;

impl Clock for BoardClock {
    fn now_us(&self) -> u64 {
        Instant::now().as_micros()
    }
    fn at(&self, at_us: u64) -> impl Future<Output = ()> {
        Timer::at(Instant::from_micros(at_us))
    }
}

/// Bank 2's last two pages.
pub struct BoardFlash;

impl FlashPages for BoardFlash {
    fn read(&self, slot: Slot) -> Result<[u8; SLOT_BYTES], EccError> {
        flash::read_slot(slot).map_err(|()| EccError)
    }
    async fn program(&self, slot: Slot, image: &[u8; SLOT_BYTES]) -> Result<(), FlashFault> {
        flash::program_slot(slot, image).await.map_err(|e| match e {
            flash::FlashError::Status(sr) => FlashFault(sr),
            flash::FlashError::Range => FlashFault(u32::MAX),
        })
    }
}

/// The control interrupt's shared state ([`crate::controller`]).
pub struct Interrupts;

impl ControlPort for Interrupts {
    fn set_reference(&self, t: f32) {
        controller::REFERENCE.store(t.to_bits(), Ordering::Relaxed);
    }
    fn set_enable(&self, on: bool) {
        controller::ENABLE.store(on, Ordering::Relaxed);
    }
    fn enabled(&self) -> bool {
        controller::ENABLE.load(Ordering::Relaxed)
    }
    fn request_reset(&self) {
        controller::RESET.store(true, Ordering::Relaxed);
    }
    fn status(&self) -> StatusFigures {
        // The last sample's (stored every period), not the 10 Hz snapshot's.
        let mf = controller::STATUS_MODE_FAULT.load(Ordering::Relaxed);
        StatusFigures {
            mode: (mf >> 8) as u8,
            fault: mf as u8,
            overruns: self.overruns(),
            torque_est: f32::from_bits(controller::STATUS_TORQUE.load(Ordering::Relaxed)),
        }
    }
    fn snapshot(&self) -> Snapshot {
        critical_section::with(|cs| controller::TELEMETRY.borrow(cs).get())
    }
    fn overruns(&self) -> u32 {
        controller::OVERRUNS.load(Ordering::Relaxed)
    }
    fn samples(&self) -> u32 {
        controller::SAMPLES.load(Ordering::Relaxed)
    }
    fn stalled(&self) -> bool {
        controller::STALLED.load(Ordering::Relaxed)
    }
    fn stall(&self) {
        controller::safe_state();
        controller::STALLED.store(true, Ordering::Relaxed);
    }
    fn request_slow_pass(&self) {
        controller::request_slow_pass();
    }
    fn hand_over(&self, lp: Loop, cfg: ValidatedConfig, _crc: u32) {
        critical_section::with(|cs| controller::PENDING.borrow_ref_mut(cs).replace((lp, cfg)));
    }
    fn running(&self, running: Option<(Slot, u32)>, damaged: bool) {
        crate::app::CONFIG_SOURCE.store(source_code(running, damaged), Ordering::Relaxed);
    }
    fn set_stream_decimation(&self, d: u32) {
        controller::STREAM_DECIMATION.store(d, Ordering::Relaxed);
    }
    fn pop_stream(&self) -> Option<StreamSample> {
        critical_section::with(|cs| controller::STREAM.borrow_ref_mut(cs).pop())
    }
}

/// The independent watchdog.
pub struct Iwdg(pub IndependentWatchdog<'static, IWDG>);

impl Watchdog for Iwdg {
    fn start(&mut self) {
        self.0.unleash();
    }
    fn pet(&mut self) {
        self.0.pet();
    }
}

/// FDCAN1 (its acceptance filter passes only `CAN_ID_CMD`).
pub struct Fdcan(pub embassy_stm32::can::Can<'static>);

impl CanPort for Fdcan {
    async fn recv(&mut self) -> Result<CanFrame, BusError> {
        loop {
            let env = self.0.read().await.map_err(|e| {
                warn!("CAN: {}", e);
                BusError
            })?;
            let embedded_can::Id::Standard(id) = env.frame.id() else { continue };
            if let Some(f) = CanFrame::new(id.as_raw(), env.frame.data()) {
                return Ok(f);
            }
        }
    }
    async fn send(&mut self, frame: &CanFrame) {
        if let Ok(f) = embassy_stm32::can::Frame::new_standard(frame.id, frame.data()) {
            self.0.write(&f).await;
        }
    }
}

/// defmt over RTT.
pub struct Defmt;

impl Events for Defmt {
    fn event(&self, e: Event) {
        match e {
            Event::Slots(a, b) => info!("configuration slots: A {}, B {}", a, b),
            Event::Loaded(slot, seq) => info!("configuration slot {} (commit {}) loaded", slot, seq),
            Event::Damaged => {
                error!("CONFIGURATION DAMAGED: no usable slot; compiled-in defaults, drive refused until a commit")
            }
            Event::Blank => info!("blank configuration slots: compiled-in defaults"),
            Event::Released => {
                warn!("no command for {} ms: drive released", firmware::link::COMMAND_TIMEOUT_MS)
            }
            Event::CommitFailed(slot, e) => error!("configuration commit to slot {}: {}", slot, e),
            Event::ReadBack(slot, state) => error!("configuration slot {} reads back as {}", slot, state),
            Event::Committed(model, slot, seq) => {
                info!("new configuration: model {}, slot {} commit {}", model, slot, seq)
            }
            Event::Stalled => error!("control interrupt stalled: bridge off, watchdog will reset"),
            Event::Telemetry(s) => {
                let o = s.out;
                info!(
                    "mode {} fault {} | T_ref {=f32} N·m T_est {=f32} N·m | B {=f32} mT i {=f32} A i_ref {=f32} A | duty {=f32} V {=f32} V | step {} cycles",
                    mode_code(o.mode),
                    o.fault.name(),
                    s.reference,
                    o.torque_est,
                    o.b * 1e3,
                    o.current,
                    o.i_ref,
                    o.duty,
                    s.supply_v,
                    s.cycles
                );
            }
            Event::Overruns(total, new) => error!("CONTROL STEP OVERRUN: {} missed deadlines ({} new)", total, new),
            Event::Bus => {}
        }
    }
}
