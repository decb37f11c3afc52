//! The control interrupt: ADC1's end-of-injected-sequence interrupt (the conversions are
//! started by TIM1's TRGO2 once per PWM period) runs `model_core::control::ControlStep::step`
//! on every sample and writes the bridge. The slow supervisor pass
//! (`ControlStep::slow`: configuration fingerprint, time step, temperature compensation)
//! runs in the same interrupt, after the compare write, on the first sample after the
//! `supervisor` task asks for it (`firmware::application::supervisor`, [`request_slow_pass`]): thread mode never
//! masks interrupts around it, and the compare write is never delayed by it.
//!
//! TIM1's update interrupt, one priority level above, is the deadline monitor: at every
//! period start it checks that the previous period's step finished; a late or stuck
//! control interrupt puts the bridge in its safe state within one PWM period and latches
//! the stall ([`firmware::bridge`]). Everything else talks to the interrupts through the
//! atomics and the critical-section cells here.

use core::cell::{Cell, RefCell};
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use critical_section::Mutex;
use embassy_stm32::adc::InjectedAdc;
use embassy_stm32::interrupt;
use embassy_stm32::peripherals::{ADC1, TIM1};
use embassy_stm32::timer::complementary_pwm::ComplementaryPwm;
use model_core::control::{ControlInput, ControlOutput, ValidatedConfig};

use firmware::application::{Snapshot, StreamRing, StreamSample};
use firmware::bridge::{self, Bridge};
pub use firmware::runner::Loop;

use crate::board;

/// What the interrupt owns.
pub struct Control {
    pub lp: Loop,
    pub cfg: ValidatedConfig,
    /// Owns TIM1 and its pins (the interrupt writes the compares and MOE by register,
    /// `board::set_compares`).
    pub _pwm: ComplementaryPwm<'static, TIM1>,
    pub adc: InjectedAdc<'static, ADC1, 3>,
    /// Timer compare value for duty 1.
    pub max_duty: u32,
    /// Core cycles in one control period (the overrun limit).
    pub period_cycles: u32,
    /// One control period, µs (1e6 / the page's control rate: 50 to 1000, exact).
    pub period_us: u32,
    /// Time of the last sample since start-up, µs (the stream's time stamps).
    pub t_us: u32,
    /// The previous step missed its deadline.
    pub overrun: bool,
    pub bridge: Bridge,
}

/// `(period_cycles, period_us)` of [`Control`] at `control_hz`.
pub fn periods(control_hz: u32) -> (u32, u32) {
    (board::CORE_HZ / control_hz, 1_000_000 / control_hz)
}

pub static CONTROL: Mutex<RefCell<Option<Control>>> = Mutex::new(RefCell::new(None));
/// A validated controller waiting to be swapped in between two samples.
pub static PENDING: Mutex<RefCell<Option<(Loop, ValidatedConfig)>>> = Mutex::new(RefCell::new(None));

/// Torque reference (f32 bits), drive enable, fault reset request (consumed by the step).
pub static REFERENCE: AtomicU32 = AtomicU32::new(0);
pub static ENABLE: AtomicBool = AtomicBool::new(false);
pub static RESET: AtomicBool = AtomicBool::new(false);
/// Samples processed and overruns since start-up.
pub static SAMPLES: AtomicU32 = AtomicU32::new(0);
pub static OVERRUNS: AtomicU32 = AtomicU32::new(0);
/// The last sample's mode and latched fault (`mode_code << 8 | fault code`) and torque
/// estimate (f32 bits, N·m), stored every sample: what `status` answers, so a fault is in
/// the reply from the period it latched in (the 10 Hz snapshot is only the log's).
pub static STATUS_MODE_FAULT: AtomicU32 = AtomicU32::new(0);
pub static STATUS_TORQUE: AtomicU32 = AtomicU32::new(0);
/// The control interrupt stopped (deadline monitor or watchdog task), or no usable
/// configuration: the bridge stays off and the step is told of an overrun (so it latches
/// the `Overrun` fault when enabled) until a reset command.
pub static STALLED: AtomicBool = AtomicBool::new(false);
/// A slow pass is due (set by the supervisor task, taken by the control interrupt).
static SLOW_DUE: AtomicBool = AtomicBool::new(false);
/// SAMPLES at the previous period start (deadline monitor).
static LAST_SEEN: AtomicU32 = AtomicU32::new(0);

/// Telemetry snapshots per second: every `control_hz / TELEMETRY_HZ`-th sample is kept
/// (2000 at 20 kHz), the same 10 Hz at every model's control rate.
pub const TELEMETRY_HZ: u32 = 10;
pub static TELEMETRY: Mutex<Cell<Snapshot>> = Mutex::new(Cell::new(Snapshot::EMPTY));

/// Every `STREAM_DECIMATION`-th sample goes to [`STREAM`] (0: none); set by the serial task.
pub static STREAM_DECIMATION: AtomicU32 = AtomicU32::new(0);
pub static STREAM: Mutex<RefCell<StreamRing>> = Mutex::new(RefCell::new(StreamRing::new()));

/// Slow passes run (telemetry).
pub static SLOW_PASSES: AtomicU32 = AtomicU32::new(0);

/// Ask for one slow supervisor pass; the control interrupt runs it after its next
/// compare write.
pub fn request_slow_pass() {
    SLOW_DUE.store(true, Ordering::Relaxed);
}

/// The bridge's safe state ([`board::safe_state`]).
#[inline(always)]
pub fn safe_state() {
    board::safe_state();
}

/// Write the bridge for one step's output: compares first, MOE a period later
/// ([`firmware::bridge`]); never while the stall is latched.
#[inline(always)]
fn drive(c: &mut Control, out: &ControlOutput, stalled: bool) {
    let (next, action) = c.bridge.next(out.pwm_enable && !stalled);
    c.bridge = next;
    match action {
        bridge::Action::Off => safe_state(),
        bridge::Action::Arm | bridge::Action::Drive => {
            let (a, b) = bridge::compares(out.compare, c.max_duty);
            board::set_compares(a, b);
            if action == bridge::Action::Drive {
                board::moe_on();
            }
        }
    }
}

/// The deadline monitor: TIM1's update interrupt at every PWM period start, above the
/// control interrupt's priority. The step of the previous period must have finished.
#[interrupt]
fn TIM1_UP_TIM16() {
    board::clear_update_flag();
    let now = SAMPLES.load(Ordering::Relaxed);
    let last = LAST_SEEN.swap(now, Ordering::Relaxed);
    if now == last && RUNNING.load(Ordering::Relaxed) {
        safe_state();
        STALLED.store(true, Ordering::Relaxed);
    }
}

/// The control interrupt has run at least once (the monitor starts then).
pub static RUNNING: AtomicBool = AtomicBool::new(false);

/// The control interrupt. It masks nothing (no `cpsid`): the deadline monitor above it
/// must be able to pre-empt a step that does not finish.
#[interrupt]
fn ADC1_2() {
    let t0 = cortex_m::peripheral::DWT::cycle_count();
    // SAFETY: a critical-section token without masking interrupts. Thread mode touches
    // CONTROL only before this interrupt is enabled, and PENDING/TELEMETRY only inside
    // real critical sections (PRIMASK), which this interrupt cannot pre-empt; the only
    // handler above this one (TIM1_UP_TIM16) touches none of the cells.
    let cs = unsafe { critical_section::CriticalSection::new() };
    {
        let mut ctl = CONTROL.borrow_ref_mut(cs);
        let Some(c) = ctl.as_mut() else {
            safe_state();
            return;
        };
        let [hall, current, supply] = c.adc.read_injected_samples();
        let supply_v = firmware::bringup::supply_volts(supply);
        if c.bridge == Bridge::Off {
            // Swap in a new configuration only while the bridge is off.
            if let Some((lp, cfg)) = PENDING.borrow_ref_mut(cs).take() {
                c.lp = lp;
                c.cfg = cfg;
                // Its control rate from the next update event on (issue 17).
                let hz = c.lp.control_hz();
                (c.period_cycles, c.period_us) = periods(hz);
                board::set_repetition(board::repetition_for(hz));
            }
        }
        let reference = f32::from_bits(REFERENCE.load(Ordering::Relaxed));
        let reset = RESET.swap(false, Ordering::Relaxed);
        if reset {
            STALLED.store(false, Ordering::Relaxed);
        }
        let stalled = STALLED.load(Ordering::Relaxed);
        // A latched stall is an overrun for the step (it trips `Overrun` after
        // `confirm_samples` if enabled, so the mode reads a fault, not Running) and the
        // bridge stays off meanwhile.
        let input = ControlInput {
            overrun: c.overrun || stalled,
            enable: ENABLE.load(Ordering::Relaxed),
            reset,
            ..ControlInput::new(hall, current, supply_v, reference)
        };
        let out = c.lp.step(&c.cfg, input);
        drive(c, &out, stalled);
        let n = SAMPLES.fetch_add(1, Ordering::Relaxed).wrapping_add(1);
        STATUS_MODE_FAULT.store(
            u32::from(model_core::protocol::mode_code(out.mode)) << 8 | u32::from(out.fault.code()),
            Ordering::Relaxed,
        );
        STATUS_TORQUE.store(out.torque_est.to_bits(), Ordering::Relaxed);
        c.t_us = c.t_us.wrapping_add(c.period_us);
        RUNNING.store(true, Ordering::Relaxed);
        let cycles = cortex_m::peripheral::DWT::cycle_count().wrapping_sub(t0);
        c.overrun = cycles > c.period_cycles;
        if c.overrun {
            OVERRUNS.fetch_add(1, Ordering::Relaxed);
        }
        if n.is_multiple_of(c.lp.control_hz() / TELEMETRY_HZ) {
            TELEMETRY.borrow(cs).set(Snapshot { out, reference, supply_v, cycles });
        }
        let d = STREAM_DECIMATION.load(Ordering::Relaxed);
        if d != 0 && n.is_multiple_of(d) {
            STREAM.borrow_ref_mut(cs).push(StreamSample { n, t_us: c.t_us, out, reference, torque_true: f32::NAN });
        }
        // The slow pass after the compare write (the board has no temperature sensor:
        // NaN, no compensation).
        if SLOW_DUE.swap(false, Ordering::Relaxed) {
            c.lp.slow(&c.cfg, f32::NAN);
            SLOW_PASSES.fetch_add(1, Ordering::Relaxed);
        }
    }
}
