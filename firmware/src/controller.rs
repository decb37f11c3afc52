//! The control interrupt: ADC1's end-of-injected-sequence interrupt (the conversions are
//! started by TIM1's TRGO2 once per PWM period) runs `model_core::control::ControlStep::step`
//! on every sample and writes the bridge. The slow supervisor pass
//! (`ControlStep::slow`: configuration fingerprint, time step, temperature compensation)
//! runs at [`SLOW_HZ`] from the `supervisor` task ([`slow_pass`]). Everything else talks to
//! the interrupt through the atomics and the critical-section cells here.

use core::cell::{Cell, RefCell};
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use critical_section::Mutex;
use embassy_stm32::adc::InjectedAdc;
use embassy_stm32::interrupt;
use embassy_stm32::peripherals::{ADC1, TIM1};
use embassy_stm32::timer::complementary_pwm::ComplementaryPwm;
use embassy_stm32::timer::Channel;
use model_core::control::{
    ConfigImage, ControlConfig, ControlInput, ControlOutput, ControlState, ControlStep, LoopMode, PageError, RateSpec,
    ValidatedConfig,
};
use model_core::models::{algebraic, bouc_wen, lugre, tanh};
use model_core::Model;

use crate::board;

/// The models this firmware is built with (any page for another model is refused).
pub enum Loop {
    Algebraic(ControlStep<algebraic::Algebraic>, ControlState<()>),
    BoucWen(ControlStep<bouc_wen::BoucWen>, ControlState<bouc_wen::State>),
    LuGre(ControlStep<lugre::LuGre>, ControlState<lugre::State>),
    Tanh(ControlStep<tanh::Tanh>, ControlState<()>),
}

fn make<M: Model>(img: &ConfigImage) -> Result<(ControlStep<M>, ControlState<M::State>), PageError> {
    let rate = img.rate.build(img.control.get().dt).map_err(PageError::Invalid)?;
    let step = ControlStep::new(img.model::<M>()?, rate).map_err(PageError::Invalid)?;
    let state = step.state();
    Ok((step, state))
}

impl Loop {
    /// The controller a page describes, validated (model parameters by `from_params`).
    pub fn from_image(img: &ConfigImage) -> Result<Self, PageError> {
        // The ids are the models' own (`Model::ID`, registered in model-core's registry).
        let id = img.model_id();
        if id == algebraic::Algebraic::ID {
            make(img).map(|(s, st)| Self::Algebraic(s, st))
        } else if id == bouc_wen::BoucWen::ID {
            make(img).map(|(s, st)| Self::BoucWen(s, st))
        } else if id == lugre::LuGre::ID {
            make(img).map(|(s, st)| Self::LuGre(s, st))
        } else if id == tanh::Tanh::ID {
            make(img).map(|(s, st)| Self::Tanh(s, st))
        } else {
            Err(PageError::WrongModel)
        }
    }

    fn slow(&mut self, cfg: &ValidatedConfig, temperature: f32) {
        match self {
            Self::Algebraic(s, st) => s.slow(cfg, st, temperature),
            Self::BoucWen(s, st) => s.slow(cfg, st, temperature),
            Self::LuGre(s, st) => s.slow(cfg, st, temperature),
            Self::Tanh(s, st) => s.slow(cfg, st, temperature),
        }
    }

    #[inline(always)]
    fn step(&mut self, cfg: &ValidatedConfig, x: ControlInput) -> ControlOutput {
        match self {
            Self::Algebraic(s, st) => s.step(cfg, st, x),
            Self::BoucWen(s, st) => s.step(cfg, st, x),
            Self::LuGre(s, st) => s.step(cfg, st, x),
            Self::Tanh(s, st) => s.step(cfg, st, x),
        }
    }
}

/// The compiled-in configuration, used when the flash page is blank or invalid: the
/// algebraic model (seed 000 eq. 14) in T with a placeholder set, torque mode, the 20 kHz
/// defaults of `ControlConfig`. The bridge stays off until a command enables it; load the
/// clutch's fitted set with `hil-sim export` (README).
pub fn default_image() -> Result<ConfigImage, PageError> {
    let dt = 1.0 / board::CONTROL_HZ as f32;
    let control = ControlConfig { mode: LoopMode::Torque, ..ControlConfig::defaults(dt) }
        .validate()
        .map_err(PageError::Invalid)?;
    ConfigImage::new(algebraic::Algebraic::ID, &[20.0, -0.05, -10.0, 0.8], RateSpec::Filtered { fc: 150.0 }, control)
}

/// What the interrupt owns.
pub struct Control {
    pub lp: Loop,
    pub cfg: ValidatedConfig,
    pub pwm: ComplementaryPwm<'static, TIM1>,
    pub adc: InjectedAdc<'static, ADC1, 3>,
    /// Timer compare value for duty 1.
    pub max_duty: u32,
    /// Core cycles in one control period (the overrun limit).
    pub period_cycles: u32,
    /// The previous step missed its deadline.
    pub overrun: bool,
    pub driving: bool,
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

/// One decimated sample for telemetry (raw output of the step; formatting and unit
/// scaling happen in the telemetry task).
#[derive(Clone, Copy, Default)]
pub struct Snapshot {
    pub out: ControlOutput,
    pub reference: f32,
    pub supply_v: f32,
    pub cycles: u32,
}

/// Every `TELEMETRY_DECIMATION`-th sample is kept.
pub const TELEMETRY_DECIMATION: u32 = 2000;
pub static TELEMETRY: Mutex<Cell<Snapshot>> = Mutex::new(Cell::new(Snapshot {
    out: ControlOutput {
        duty: 0.0,
        compare: 0,
        pwm_enable: false,
        b: 0.0,
        current: 0.0,
        torque_est: 0.0,
        i_ref: 0.0,
        v_cmd: 0.0,
        mode: model_core::control::Mode::Init,
        fault: model_core::control::FaultCode::None,
        flags: 0,
    },
    reference: 0.0,
    supply_v: 0.0,
    cycles: 0,
}));

/// Rate of the slow supervisor pass (the step trips `SupervisorStalled` after 0.1 s
/// without one).
pub const SLOW_HZ: u64 = 1_000;
/// Slow passes run (telemetry).
pub static SLOW_PASSES: AtomicU32 = AtomicU32::new(0);

/// One slow supervisor pass over the running controller (a short critical section: the
/// fingerprint of the configuration, a few hundred instructions). The board has no
/// temperature sensor: NaN (no compensation).
pub fn slow_pass() {
    critical_section::with(|cs| {
        if let Some(c) = CONTROL.borrow_ref_mut(cs).as_mut() {
            c.lp.slow(&c.cfg, f32::NAN);
        }
    });
    SLOW_PASSES.fetch_add(1, Ordering::Relaxed);
}

/// The bridge's safe state: main output enable off, so every switch takes its idle state
/// (off; OSSI set at start-up) and the coil current decays through the body diodes. A
/// register write through the PAC so that the panic and fault handlers can call it
/// whatever the rest of the program holds.
#[inline(always)]
pub fn safe_state() {
    embassy_stm32::pac::TIM1.bdtr().modify(|w| w.set_moe(false));
}

/// Sign-magnitude drive: positive duty switches half-bridge A with |d| and holds B's low
/// side on, negative the other way round.
fn drive(c: &mut Control, out: &ControlOutput) {
    if !out.pwm_enable {
        safe_state();
        c.driving = false;
        return;
    }
    let mag = out.compare.unsigned_abs().min(c.max_duty);
    let (a, b) = if out.compare >= 0 { (mag, 0) } else { (0, mag) };
    c.pwm.set_duty(Channel::Ch1, a);
    c.pwm.set_duty(Channel::Ch2, b);
    if !c.driving {
        c.pwm.set_master_output_enable(true);
        c.driving = true;
    }
}

#[interrupt]
fn ADC1_2() {
    let t0 = cortex_m::peripheral::DWT::cycle_count();
    critical_section::with(|cs| {
        let mut ctl = CONTROL.borrow_ref_mut(cs);
        let Some(c) = ctl.as_mut() else {
            safe_state();
            return;
        };
        let [hall, current, supply] = c.adc.read_injected_samples();
        let supply_v = f32::from(supply) * (board::VREF / 4095.0 * board::SUPPLY_DIVIDER);
        if !c.driving {
            // Swap in a new configuration only while the bridge is off.
            if let Some((lp, cfg)) = PENDING.borrow_ref_mut(cs).take() {
                c.lp = lp;
                c.cfg = cfg;
            }
        }
        let reference = f32::from_bits(REFERENCE.load(Ordering::Relaxed));
        let input = ControlInput {
            overrun: c.overrun,
            enable: ENABLE.load(Ordering::Relaxed),
            reset: RESET.swap(false, Ordering::Relaxed),
            ..ControlInput::new(hall, current, supply_v, reference)
        };
        let out = c.lp.step(&c.cfg, input);
        drive(c, &out);
        let n = SAMPLES.fetch_add(1, Ordering::Relaxed).wrapping_add(1);
        let cycles = cortex_m::peripheral::DWT::cycle_count().wrapping_sub(t0);
        c.overrun = cycles > c.period_cycles;
        if c.overrun {
            OVERRUNS.fetch_add(1, Ordering::Relaxed);
        }
        if n.is_multiple_of(TELEMETRY_DECIMATION) {
            TELEMETRY.borrow(cs).set(Snapshot { out, reference, supply_v, cycles });
        }
    });
}
