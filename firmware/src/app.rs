//! The embassy application (bare-metal target only).
//!
//! Start-up: clocks (170 MHz from the 24 MHz crystal; ADC kernel clock PLL P, FDCAN
//! kernel clock HSE), the reset cause, the watchdog frozen under a debugger, the
//! configuration from the newer valid A/B slot ([`firmware::slots`]; the compiled-in
//! defaults on a blank board, reported as a fault when the slots hold something unusable),
//! TIM1 centre-aligned complementary PWM with dead time whose TRGO2 (update event at the
//! counter underflow, once per period via the repetition counter) starts ADC1's injected
//! sequence (Hall, coil current, supply), the comparator over-current trip into TIM1's
//! break and BDTR locked, the interrupts (deadline monitor above the control interrupt,
//! above CAN, above the time driver; [`crate::controller`]), then the tasks of
//! [`firmware::application`] (CAN and serial commands with the command timeout, the
//! supervisor's slow-pass requests, decimated defmt telemetry, the watchdog) over this
//! board's ports ([`crate::board::ports`]): this file keeps only their embassy task
//! wrappers and the peripheral set-up.

use core::sync::atomic::Ordering;

use defmt::{error, info};
use defmt_rtt as _;
use embassy_executor::Spawner;
use embassy_stm32::adc::{Adc, AdcConfig, Exten, SampleTime};
use embassy_stm32::can::config::{GlobalFilter, NominalBitTiming};
use embassy_stm32::can::filter::{Action, FilterType, StandardFilter, StandardFilterSlot};
use embassy_stm32::can::{self, CanConfigurator};
use embassy_stm32::interrupt::{InterruptExt, Priority};
use embassy_stm32::peripherals::FDCAN1;
use embassy_stm32::peripherals::LPUART1;
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::complementary_pwm::{ComplementaryPwm, Mms2, Ossi, Ossr};
use embassy_stm32::timer::low_level::CountingMode;
use embassy_stm32::timer::Channel;
use embassy_stm32::usart::{BufferedInterruptHandler, BufferedUart};
use embassy_stm32::wdg::IndependentWatchdog;
use embassy_stm32::{bind_interrupts, interrupt, Config};
use firmware::application::{self, store, App, ControlPort, Shared};
use firmware::bringup;

use crate::board::ports::{BoardClock, BoardFlash, Defmt, Fdcan, Interrupts, Iwdg};
use crate::board::{self, Board};
use crate::controller::{self, Control};
use crate::safety::fatal;

bind_interrupts!(struct Irqs {
    FDCAN1_IT0 => can::IT0InterruptHandler<FDCAN1>;
    FDCAN1_IT1 => can::IT1InterruptHandler<FDCAN1>;
    LPUART1 => BufferedInterruptHandler<LPUART1>;
});

/// Clock tree: the Nucleo's 24 MHz crystal / 6 × 85 = 340 MHz VCO; / 2 on PLL R = 170 MHz
/// SYSCLK, with range-1 boost mode (required above 150 MHz); / 8 on PLL P = 42.5 MHz for
/// the ADC kernel clock (≤ 60 MHz; embassy's default mux leaves `adc12sel` disabled and
/// `Adc::new` would panic). FDCAN's kernel clock is the crystal itself (24 MHz: 24 time
/// quanta a bit at 1 Mbit/s, crystal accuracy; `fdcansel` resets to HSE, which must be
/// on). AHB/APB1/APB2 undivided (170 MHz), so TIM1 counts at 170 MHz.
fn clocks() -> Config {
    use embassy_stm32::rcc::{mux, Hse, HseMode, Pll, PllMul, PllPDiv, PllPreDiv, PllRDiv, PllSource, Sysclk};
    let mut config = Config::default();
    config.rcc.hse = Some(Hse { freq: Hertz(board::HSE_HZ), mode: HseMode::Oscillator });
    config.rcc.pll = Some(Pll {
        source: PllSource::HSE,
        prediv: PllPreDiv::DIV6,
        mul: PllMul::MUL85,
        divp: Some(PllPDiv::DIV8),
        divq: None,
        divr: Some(PllRDiv::DIV2),
    });
    config.rcc.sys = Sysclk::PLL1_R;
    config.rcc.boost = true;
    config.rcc.mux.adc12sel = mux::Adcsel::PLL1_P;
    config.rcc.mux.fdcansel = mux::Fdcansel::HSE;
    config
}

/// Which configuration runs, for telemetry and the firmware-in-the-loop test
/// ([`firmware::application::store::source_code`]). `#[used]`: kept (and its stores with
/// it) for the debugger and the emulator, which read it by symbol.
#[used]
pub static CONFIG_SOURCE: core::sync::atomic::AtomicU32 = core::sync::atomic::AtomicU32::new(0);

/// What the link tasks share (the running configuration is set at start-up).
static SHARED: Shared = Shared::new(None, false, 0);

/// The application over this board's ports.
type Board0 = App<'static, BoardClock, BoardFlash, Interrupts, Defmt>;
const APP: Board0 = App { clock: &BoardClock, flash: &BoardFlash, ctl: &Interrupts, events: &Defmt, shared: &SHARED };

#[embassy_executor::main]
async fn main(spawner: Spawner) {
    let p = embassy_stm32::init(clocks());
    // Until TIM1 is set up its outputs are GPIO inputs (the gate drivers' pull-downs keep
    // the bridge off); from then on MOE is off until the first enabled step.
    let b = Board::new(p);
    let cause = board::reset_cause();
    board::freeze_watchdog_in_debug();
    info!("MR clutch controller, SYSCLK 170 MHz, PWM {} Hz, reset cause {}", board::CONTROL_HZ, cause);
    if cause.is_fault() {
        error!("RESET BY {}: the previous run stopped with the bridge switching", cause);
    }

    let Some(mut cp) = cortex_m::Peripherals::take() else { fatal("core peripherals taken") };
    cp.DCB.enable_trace();
    cp.DWT.enable_cycle_counter();

    let Ok(loaded) = store::load(&BoardFlash, &Defmt) else { fatal("compiled-in configuration rejected") };
    SHARED.booted(loaded.running, loaded.damaged, loaded.crc);
    SHARED.set_limits(&loaded.cfg, loaded.lp.control_hz());
    Interrupts.running(loaded.running, loaded.damaged);
    let _flash_owner = b.flash;

    // Bridge: centre-aligned PWM at CONTROL_HZ, complementary outputs with dead time,
    // all switches off when the main output is disabled (OSSI/OSSR, idle level low).
    let mut pwm = ComplementaryPwm::new(
        b.tim1,
        Some(b.bridge_a.0),
        Some(b.bridge_a.1),
        Some(b.bridge_b.0),
        Some(b.bridge_b.1),
        None,
        None,
        None,
        None,
        Hertz(board::CONTROL_HZ),
        CountingMode::CenterAlignedBothInterrupts,
    );
    controller::safe_state();
    // OIS/OISN stay at their reset value 0: with MOE off both outputs of each leg sit at
    // the inactive level (both switches off, the coil free-wheels into the supply).
    pwm.set_off_state_selection_idle(Ossi::IDLE_LEVEL);
    pwm.set_off_state_selection_run(Ossr::IDLE_LEVEL);
    pwm.set_dead_time(board::DEAD_TIME_DTG);
    pwm.set_mms2(Mms2::UPDATE);
    pwm.set_duty(Channel::Ch1, 0);
    pwm.set_duty(Channel::Ch2, 0);
    pwm.enable(Channel::Ch1);
    pwm.enable(Channel::Ch2);
    // One update event per PWM period at the counter underflow (the centre of the
    // high-side on-time), whatever the calls above did to the counter: stop, count from
    // 0 up, repetition counter 1, load it with UG, start ([`board::align_update`]).
    board::align_update(board::repetition_for(loaded.lp.control_hz()));
    controller::safe_state();
    // Centre-aligned: a compare of ARR + 1 keeps the output active the whole period.
    let max_duty = pwm.get_max_duty() + 1;
    if max_duty != board::PWM_COUNTS {
        fatal("TIM1 counts for duty 1 differ from firmware::bringup::PWM_COUNTS");
    }
    let threshold = bringup::over_current_counts(loaded.cfg.get()).unwrap_or(4095);
    board::arm_break(threshold);
    board::lock_bridge_config();
    info!("PWM: {} counts for duty 1; over-current comparator at {} counts", max_duty, threshold);
    info!("control {} Hz ({})", loaded.lp.control_hz(), loaded.lp.model_id());

    // ADC1 injected sequence started by TIM1 TRGO2 (rising edge of the update pulse),
    // end-of-sequence interrupt. The supply's divider (10 kΩ / 1 kΩ ≈ 909 Ω source) gets
    // 47.5 cycles (1.1 µs at 42.5 MHz) to charge the sampling capacitor to 12 bits.
    let adc = Adc::new(b.adc, AdcConfig::default());
    let adc = adc.setup_injected_conversions(
        [(b.hall, SampleTime::CYCLES12_5), (b.current, SampleTime::CYCLES12_5), (b.supply, SampleTime::CYCLES47_5)],
        embassy_stm32::triggers::TIM1_TRGO2,
        Exten::RISING_EDGE,
        true,
    );

    if loaded.damaged {
        controller::STALLED.store(true, Ordering::Relaxed);
    }
    let (period_cycles, period_us) = controller::periods(loaded.lp.control_hz());
    critical_section::with(|cs| {
        controller::CONTROL.borrow_ref_mut(cs).replace(Control {
            lp: loaded.lp,
            cfg: loaded.cfg,
            _pwm: pwm,
            adc,
            max_duty,
            period_cycles,
            period_us,
            t_us: 0,
            overrun: false,
            bridge: firmware::bridge::Bridge::Off,
        });
    });
    // Priorities (lower is more urgent): the deadline monitor, then the control step,
    // then CAN, then the time driver (TIM15, sharing its vector with TIM1's break).
    interrupt::TIM1_UP_TIM16.set_priority(Priority::P0);
    interrupt::ADC1_2.set_priority(Priority::P1);
    interrupt::FDCAN1_IT0.set_priority(Priority::P3);
    interrupt::FDCAN1_IT1.set_priority(Priority::P3);
    interrupt::TIM1_BRK_TIM15.set_priority(Priority::P4);
    board::enable_update_interrupt();
    // SAFETY: the handlers touch `CONTROL`/`PENDING`/`TELEMETRY` and the atomics only (see
    // `controller::ADC1_2` for why it needs no masking); they are installed now that
    // `CONTROL` holds the peripherals they drive.
    unsafe {
        interrupt::ADC1_2.enable();
        interrupt::TIM1_UP_TIM16.enable();
    }

    let can = start_can(b.can, b.can_rx, b.can_tx);
    let uart = start_uart(b.uart, b.uart_rx, b.uart_tx);

    let iwdg = IndependentWatchdog::new(b.iwdg, board::WATCHDOG_US);
    match (telemetry(), commands(can), serial(uart), supervisor()) {
        (Ok(t), Ok(c), Ok(u), Ok(s)) => {
            spawner.spawn(t);
            spawner.spawn(c);
            spawner.spawn(u);
            spawner.spawn(s);
        }
        _ => fatal("spawning tasks"),
    }
    info!("running");
    application::watchdog::run(APP, &mut Iwdg(iwdg)).await;
}

/// LPUART1 at [`board::UART_BAUD`], 8N1, interrupt-driven with its buffers.
fn start_uart(
    uart: embassy_stm32::Peri<'static, LPUART1>,
    rx: embassy_stm32::Peri<'static, embassy_stm32::peripherals::PA3>,
    tx: embassy_stm32::Peri<'static, embassy_stm32::peripherals::PA2>,
) -> BufferedUart<'static> {
    let (Some(tx_buf), Some(rx_buf)) =
        (cortex_m::singleton!(: [u8; 512] = [0; 512]), cortex_m::singleton!(: [u8; 256] = [0; 256]))
    else {
        fatal("UART buffers")
    };
    let mut config = embassy_stm32::usart::Config::default();
    config.baudrate = board::UART_BAUD;
    match BufferedUart::new(uart, rx, tx, tx_buf, rx_buf, Irqs, config) {
        Ok(u) => u,
        Err(_) => fatal("LPUART1 configuration"),
    }
}

/// FDCAN1 in normal mode: bit timing from the crystal (`firmware::can_timing`), one
/// standard filter for `CAN_ID_CMD` into FIFO 0, every other frame rejected.
fn start_can(
    can: embassy_stm32::Peri<'static, FDCAN1>,
    rx: embassy_stm32::Peri<'static, embassy_stm32::peripherals::PA11>,
    tx: embassy_stm32::Peri<'static, embassy_stm32::peripherals::PA12>,
) -> embassy_stm32::can::Can<'static> {
    let mut can = CanConfigurator::new(can, rx, tx, Irqs);
    let Some(t) = firmware::can_timing::nominal(board::HSE_HZ, board::CAN_BITRATE) else {
        fatal("no exact CAN bit timing from the crystal")
    };
    let timing = (
        core::num::NonZeroU16::new(t.prescaler),
        core::num::NonZeroU8::new(t.seg1),
        core::num::NonZeroU8::new(t.seg2),
        core::num::NonZeroU8::new(t.sjw),
    );
    let (Some(prescaler), Some(seg1), Some(seg2), Some(sync_jump_width)) = timing else {
        fatal("CAN bit timing out of range")
    };
    let config = can
        .config()
        .set_nominal_bit_timing(NominalBitTiming { prescaler, seg1, seg2, sync_jump_width })
        .set_global_filter(GlobalFilter::reject_all());
    can.set_config(config);
    let Some(cmd_id) = embedded_can::StandardId::new(board::CAN_ID_CMD) else { fatal("CAN id") };
    can.properties().set_standard_filter(
        StandardFilterSlot::_0,
        StandardFilter { filter: FilterType::DedicatedSingle(cmd_id), action: Action::StoreInFifo0 },
    );
    can.into_normal_mode()
}

/// [`application::supervisor`].
#[embassy_executor::task]
async fn supervisor() {
    application::supervisor::run(APP).await
}

/// [`application::telemetry`].
#[embassy_executor::task]
async fn telemetry() {
    application::telemetry::run(APP).await
}

/// [`application::can`] on FDCAN1 (its filter lets only `CAN_ID_CMD` into the FIFO).
#[embassy_executor::task]
async fn commands(can: embassy_stm32::can::Can<'static>) {
    application::can::run(APP, Fdcan(can)).await
}

/// [`application::serial`] on LPUART1 (the ST-LINK virtual COM port).
#[embassy_executor::task]
async fn serial(uart: BufferedUart<'static>) {
    let (tx, rx) = uart.split();
    application::serial::run(APP, rx, tx).await
}
