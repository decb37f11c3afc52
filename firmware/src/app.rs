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
//! above CAN, above the time driver; [`crate::controller`]), then four tasks: CAN commands
//! ([`model_core::protocol`], with the command timeout of [`firmware::link`]), the
//! supervisor's slow-pass requests, decimated defmt telemetry, and the watchdog.

use core::sync::atomic::Ordering;

use defmt::{error, info, warn};
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
use embassy_time::{Duration, Instant, Ticker, Timer};
use firmware::bringup::{self, BoardMismatch};
use firmware::link::{LinkAction, LinkWatch};
use firmware::slots::{self, Boot, Slot, SlotState};
use model_core::control::{ConfigImage, PageError, ValidatedConfig};
use model_core::protocol::device::{Action as Do, Device, StatusFigures};
use model_core::protocol::frame::{encode, Deframer, MAX_ENCODED};
use model_core::protocol::telemetry::Telemetry;
use model_core::protocol::{mode_code, Command, Nack, Response, FRAME};

use crate::board::{self, flash, Board};
use crate::controller::{self, Control, Loop, Snapshot};
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

/// A page error for the log (a name: formatting the numbers in it would pull core's float
/// formatting into flash; `hil-sim export` gives the full message on the host).
fn page_error(e: &model_core::control::PageError) -> &'static str {
    use model_core::control::PageError as E;
    match e {
        E::BadMagic => "blank or foreign page",
        E::UnsupportedVersion(_) => "unsupported format version",
        E::Malformed(what) => what,
        E::CrcMismatch { .. } => "CRC mismatch",
        E::Invalid(_) => "settings or model parameters out of range",
        E::WrongModel => "model not built into this firmware",
    }
}

/// Which configuration runs, for telemetry and the firmware-in-the-loop test:
/// `seq << 2 | slot` with slot 1 = A, 2 = B; 0 = compiled-in defaults on a blank board,
/// 3 = defaults because the slots are damaged. `#[used]`: kept (and its stores with it)
/// for the debugger and the emulator, which read it by symbol.
#[used]
pub static CONFIG_SOURCE: core::sync::atomic::AtomicU32 = core::sync::atomic::AtomicU32::new(0);

fn source_code(running: Option<(Slot, u32)>, damaged: bool) -> u32 {
    match running {
        Some((Slot::A, seq)) => seq << 2 | 1,
        Some((Slot::B, seq)) => seq << 2 | 2,
        None if damaged => 3,
        None => 0,
    }
}

/// Started with no usable configuration (the loop is held in a fault until a commit).
static DAMAGED: core::sync::atomic::AtomicBool = core::sync::atomic::AtomicBool::new(false);

/// What one slot holds.
fn inspect(slot: Slot) -> (SlotState, Option<(Loop, ValidatedConfig)>) {
    let Ok(bytes) = flash::read_slot(slot) else {
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
    match ConfigImage::decode(image).and_then(|img| runnable(&img)) {
        Ok(c) => (SlotState::Valid(seq), Some(c)),
        Err(e) => (SlotState::Unusable(page_error(&e)), None),
    }
}

/// A decoded page as a controller, checked against the board.
fn runnable(img: &ConfigImage) -> Result<(Loop, ValidatedConfig), PageError> {
    bringup::check_board(&img.control, board::PWM_COUNTS).map_err(|m| match m {
        BoardMismatch::PwmCounts => PageError::Malformed("pwm_counts is not the timer's"),
        BoardMismatch::SamplePeriod => PageError::Malformed("dt is not the control period"),
        BoardMismatch::OverCurrentRange => PageError::Malformed("over_current beyond the comparator"),
    })?;
    Loop::from_image(img).map(|lp| (lp, img.control))
}

/// The configuration that boots: the newer valid slot, or the defaults (blank board), or
/// the defaults with the loop held in a fault until a valid page is committed.
struct Loaded {
    lp: Loop,
    cfg: ValidatedConfig,
    running: Option<(Slot, u32)>,
    damaged: bool,
}

fn load_config() -> Loaded {
    let (sa, ca) = inspect(Slot::A);
    let (sb, cb) = inspect(Slot::B);
    info!("configuration slots: A {}, B {}", sa, sb);
    let boot = slots::choose(sa, sb);
    let chosen = match boot {
        Boot::Slot(Slot::A, _) => ca,
        Boot::Slot(Slot::B, _) => cb,
        Boot::Blank | Boot::Damaged => None,
    };
    if let (Boot::Slot(slot, seq), Some((lp, cfg))) = (boot, chosen) {
        info!("configuration slot {} (commit {}) loaded", slot, seq);
        return Loaded { lp, cfg, running: Some((slot, seq)), damaged: false };
    }
    let damaged = boot == Boot::Damaged;
    if damaged {
        error!("CONFIGURATION DAMAGED: no usable slot; compiled-in defaults, drive refused until a commit");
    } else {
        info!("blank configuration slots: compiled-in defaults");
    }
    match controller::default_image().and_then(|img| runnable(&img)) {
        Ok((lp, cfg)) => Loaded { lp, cfg, running: None, damaged },
        Err(_) => fatal("compiled-in configuration rejected"),
    }
}

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

    let loaded = load_config();
    CONFIG_SOURCE.store(source_code(loaded.running, loaded.damaged), Ordering::Relaxed);
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
    board::align_update(board::repetition_for(loaded.lp.control_hz())); // s17b: the page's control rate
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
    info!("control {} Hz ({})", loaded.lp.control_hz(), loaded.lp.model_id()); // s17b

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
        DAMAGED.store(true, Ordering::Relaxed);
        controller::STALLED.store(true, Ordering::Relaxed);
    }
    controller::CONTROL_HZ_NOW.store(loaded.lp.control_hz(), Ordering::Relaxed); // s17b
    critical_section::with(|cs| {
        controller::CONTROL.borrow_ref_mut(cs).replace(Control {
            lp: loaded.lp,
            cfg: loaded.cfg,
            _pwm: pwm,
            adc,
            max_duty,
            period_cycles: board::CORE_HZ / controller::CONTROL_HZ_NOW.load(Ordering::Relaxed), // s17b
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
    critical_section::with(|cs| RUNNING_CONFIG.borrow(cs).set(loaded.running));
    ACTIVE_CRC.store(loaded.running.map_or(0, |(slot, _)| slot_crc(slot)), Ordering::Relaxed); // s17b
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
    watchdog(iwdg).await;
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

/// Pet the independent watchdog only while the control interrupt keeps running: a stalled
/// loop resets the chip, and the bridge is off from reset on.
async fn watchdog(mut iwdg: IndependentWatchdog<'static, embassy_stm32::peripherals::IWDG>) -> ! {
    iwdg.unleash();
    let mut last = controller::SAMPLES.load(Ordering::Relaxed);
    let mut ticker = Ticker::every(Duration::from_millis(10));
    loop {
        ticker.next().await;
        let now = controller::SAMPLES.load(Ordering::Relaxed);
        if now != last && !controller::STALLED.load(Ordering::Relaxed) {
            iwdg.pet();
        } else if now == last {
            // Bridge off and the stall latched, so the loop reports it (the mode does not
            // read Running with the bridge off) should the interrupt come back.
            controller::safe_state();
            controller::STALLED.store(true, Ordering::Relaxed);
            error!("control interrupt stalled: bridge off, watchdog will reset");
        } else {
            // Stalled but sampling again (deadline monitor, damaged configuration): the
            // loop holds the bridge off in its fault; keep the watchdog fed.
            iwdg.pet();
        }
        last = now;
    }
}

/// Requests the slow supervisor pass of the control step at `SLOW_HZ` (run by the control
/// interrupt after a compare write; the step trips `SupervisorStalled` if this task stops).
#[embassy_executor::task]
async fn supervisor() {
    let mut ticker = Ticker::every(Duration::from_hz(controller::SLOW_HZ));
    loop {
        ticker.next().await;
        controller::request_slow_pass();
    }
}

/// Decimated telemetry in SI units (10 Hz), overruns reported loudly.
#[embassy_executor::task]
async fn telemetry() {
    let mut ticker = Ticker::every(Duration::from_millis(100));
    let mut overruns = 0;
    loop {
        ticker.next().await;
        let s: Snapshot = critical_section::with(|cs| controller::TELEMETRY.borrow(cs).get());
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
        let now = controller::OVERRUNS.load(Ordering::Relaxed);
        if now != overruns {
            error!("CONTROL STEP OVERRUN: {} missed deadlines ({} new)", now, now.wrapping_sub(overruns));
            overruns = now;
        }
    }
}

fn reply(r: Response) -> Option<embassy_stm32::can::Frame> {
    let mut buf = [0u8; FRAME];
    let n = r.encode(&mut buf);
    embassy_stm32::can::Frame::new_standard(board::CAN_ID_REPLY, buf.get(..n)?).ok()
}

/// The configuration running (slot, commit sequence), shared by the link tasks.
static RUNNING_CONFIG: critical_section::Mutex<core::cell::Cell<Option<(Slot, u32)>>> =
    critical_section::Mutex::new(core::cell::Cell::new(None));
/// A commit is being written (the other link's commit is refused meanwhile).
// s17b (issue 17): the running page's CRC-32, shared by both links' page-CRC query: set at
// boot from the running slot and by a commit over either link.
static ACTIVE_CRC: core::sync::atomic::AtomicU32 = core::sync::atomic::AtomicU32::new(0);

/// CRC-32 of the page in `slot` (0 when it does not decode). s17b.
fn slot_crc(slot: Slot) -> u32 {
    let Ok(bytes) = flash::read_slot(slot) else { return 0 };
    ConfigImage::decode(bytes.get(..slots::IMAGE_BYTES).unwrap_or(&[])).map_or(0, |img| img.crc())
}

static COMMITTING: core::sync::atomic::AtomicBool = core::sync::atomic::AtomicBool::new(false);
/// The command timeout of both links together (`firmware::link`).
static LINK: critical_section::Mutex<core::cell::Cell<LinkWatch>> =
    critical_section::Mutex::new(core::cell::Cell::new(LinkWatch::new(board::COMMAND_TIMEOUT_MS, 0)));

fn now_ms() -> u64 {
    Instant::now().as_millis()
}

/// Release the drive when no link has been heard for `COMMAND_TIMEOUT_MS`.
fn watch_link(device: &mut Device) {
    let enabled = controller::ENABLE.load(Ordering::Relaxed);
    let action = critical_section::with(|cs| {
        let mut l = LINK.borrow(cs).get();
        let a = l.poll(now_ms(), enabled);
        LINK.borrow(cs).set(l);
        a
    });
    if action == LinkAction::Release {
        controller::ENABLE.store(false, Ordering::Relaxed);
        controller::REFERENCE.store(0, Ordering::Relaxed);
        warn!("no command for {} ms: drive released", board::COMMAND_TIMEOUT_MS);
    }
    if !controller::ENABLE.load(Ordering::Relaxed) {
        device.released();
    }
}

/// One frame from a link through the shared command handler
/// (`model_core::protocol::device`): its action done, its reply returned.
async fn serve(device: &mut Device, data: &[u8]) -> Option<Response> {
    if Command::decode(data).is_ok() {
        critical_section::with(|cs| {
            let mut l = LINK.borrow(cs).get();
            l.heard(now_ms());
            LINK.borrow(cs).set(l);
        });
    }
    device.set_active_crc(ACTIVE_CRC.load(Ordering::Relaxed)); // s17b: the running page's, not this link's last commit
    match device.handle(data) {
        (Do::None, r) => r,
        (Do::Reference(t), r) => {
            controller::REFERENCE.store(t.to_bits(), Ordering::Relaxed);
            r
        }
        (Do::Enable(e), r) => {
            controller::ENABLE.store(e, Ordering::Relaxed);
            r
        }
        (Do::Reset, r) => {
            controller::RESET.store(true, Ordering::Relaxed);
            r
        }
        (Do::Status, _) => {
            let s = critical_section::with(|cs| controller::TELEMETRY.borrow(cs).get());
            Some(device.status(StatusFigures {
                mode: mode_code(s.out.mode),
                fault: s.out.fault.code(),
                overruns: controller::OVERRUNS.load(Ordering::Relaxed),
                torque_est: s.out.torque_est,
            }))
        }
        (Do::Commit, _) => {
            let result = match (device.take_page(), COMMITTING.swap(true, Ordering::Acquire)) {
                (_, true) => Err(Nack::Busy),
                (None, false) => Err(Nack::Sequence),
                (Some(img), false) => {
                    let running = critical_section::with(|cs| RUNNING_CONFIG.borrow(cs).get());
                    let r = commit(device.page_bytes(), &img, running).await.map(|now| (now, img.crc()));
                    COMMITTING.store(false, Ordering::Release);
                    r
                }
            };
            if let Ok((now, crc)) = result {
                critical_section::with(|cs| RUNNING_CONFIG.borrow(cs).set(Some(now)));
                ACTIVE_CRC.store(crc, Ordering::Relaxed); // s17b
                device.set_active_crc(crc);
            }
            Some(device.committed(result.map(|_| ())))
        }
    }
}

/// CAN commands (protocol in `model_core::protocol`). The acceptance filter lets only
/// `CAN_ID_CMD` into the FIFO. A drive enabled with no command on either link for
/// `COMMAND_TIMEOUT_MS` is released (`firmware::link`).
#[embassy_executor::task]
async fn commands(mut can: embassy_stm32::can::Can<'static>) {
    let mut device = Device::default();
    loop {
        let wait = Duration::from_millis(board::COMMAND_TIMEOUT_MS / 4);
        let got = embassy_time::with_timeout(wait, can.read()).await;
        watch_link(&mut device);
        let env = match got {
            Err(_timeout) => continue,
            Ok(Ok(env)) => env,
            Ok(Err(e)) => {
                warn!("CAN: {}", e);
                Timer::after_millis(1).await;
                continue;
            }
        };
        let id = match env.frame.id() {
            embedded_can::Id::Standard(id) => id.as_raw(),
            embedded_can::Id::Extended(_) => continue,
        };
        if id != board::CAN_ID_CMD {
            continue;
        }
        let answer = serve(&mut device, env.frame.data()).await;
        if let Some(frame) = answer.and_then(reply) {
            can.write(&frame).await;
        }
    }
}

/// The serial link on LPUART1 (the ST-LINK virtual COM port): the same commands, each
/// frame COBS-encoded with a CRC-32 (`model_core::protocol::frame`), and the telemetry
/// stream: the control interrupt's samples at the decimation the host asked for, numbered
/// by sample index (a gap is a lost frame), in SI units.
#[embassy_executor::task]
async fn serial(uart: BufferedUart<'static>) {
    use embedded_io_async::{Read, Write};
    let (mut tx, mut rx) = uart.split();
    let mut device = Device::default();
    let mut deframer = Deframer::default();
    let mut buf = [0u8; 64];
    loop {
        let got = embassy_time::with_timeout(Duration::from_micros(500), rx.read(&mut buf)).await;
        watch_link(&mut device);
        let n = match got {
            Ok(Ok(n)) => n,
            Ok(Err(_)) | Err(_) => 0,
        };
        for &byte in buf.get(..n).unwrap_or(&[]) {
            let Some(Ok(payload)) = deframer.push(byte) else { continue };
            if let Some(r) = serve(&mut device, payload).await {
                let mut f = [0u8; FRAME];
                let m = r.encode(&mut f);
                let mut out = [0u8; MAX_ENCODED];
                let k = encode(f.get(..m).unwrap_or(&[]), &mut out);
                let _ = tx.write_all(out.get(..k).unwrap_or(&[])).await;
            }
        }
        let d = u32::from(device.decimation());
        controller::STREAM_DECIMATION.store(d, Ordering::Relaxed);
        while let Some(s) = critical_section::with(|cs| controller::STREAM.borrow_ref_mut(cs).pop()) {
            let t = Telemetry {
                // s17b: sample index × the running rate's period (since the last rate change).
                t_us: s.n.wrapping_mul(1_000_000 / controller::CONTROL_HZ_NOW.load(Ordering::Relaxed).max(1)),
                b: s.out.b,
                current: s.out.current,
                torque_est: s.out.torque_est,
                reference: s.reference,
                duty: s.out.duty,
                mode: mode_code(s.out.mode),
                fault: s.out.fault.code(),
                torque_true: f32::NAN,
            };
            let seq = (s.n / d.max(1)) as u16;
            let mut out = [0u8; MAX_ENCODED];
            let k = encode(&t.encode(seq), &mut out);
            let _ = tx.write_all(out.get(..k).unwrap_or(&[])).await;
        }
    }
}

/// Validate the received page, write it to the slot not running (erase, image, commit
/// record last; the waits yield, so the control interrupt and the watchdog task keep
/// running), read it back, hand it to the control interrupt.
async fn commit(
    bytes: &[u8; model_core::control::page::PAGE_BYTES],
    img: &ConfigImage,
    running: Option<(Slot, u32)>,
) -> Result<(Slot, u32), Nack> {
    if controller::ENABLE.load(Ordering::Relaxed) {
        return Err(Nack::Busy);
    }
    // Checked now, built again once written: a controller held across the flash waits
    // would sit in both link tasks' futures (11 KB each with every model built in).
    runnable(img).map(drop).map_err(|_| Nack::InvalidPage)?;
    let (slot, seq) = slots::commit_target(running);
    let image = slots::slot_image(bytes, seq).ok_or(Nack::InvalidPage)?;
    flash::program_slot(slot, &image).await.map_err(|e| {
        error!("configuration commit to slot {}: {}", slot, e);
        Nack::Flash
    })?;
    match inspect(slot) {
        (SlotState::Valid(s), _) if s == seq => {}
        (state, _) => {
            error!("configuration slot {} reads back as {}", slot, state);
            return Err(Nack::Flash);
        }
    }
    let built = runnable(img).map_err(|_| Nack::InvalidPage)?;
    critical_section::with(|cs| controller::PENDING.borrow_ref_mut(cs).replace(built));
    // A board held by a damaged configuration runs again once a good page is committed.
    if DAMAGED.swap(false, Ordering::Relaxed) {
        controller::RESET.store(true, Ordering::Relaxed);
    }
    CONFIG_SOURCE.store(source_code(Some((slot, seq)), false), Ordering::Relaxed);
    info!("new configuration: model {}, slot {} commit {}", img.model_id(), slot, seq);
    Ok((slot, seq))
}
