//! The embassy application (bare-metal target only).
//!
//! Start-up: clocks (170 MHz), the bridge in its safe state, the configuration page from
//! flash (or the compiled-in defaults when it is blank or invalid), TIM1 centre-aligned
//! complementary PWM with dead time whose TRGO2 (update event, once per period via the
//! repetition counter) starts ADC1's injected sequence (Hall, coil current, supply), the
//! control interrupt at the highest priority ([`crate::controller`]), then three tasks:
//! CAN commands ([`model_core::protocol`]), decimated defmt telemetry, and the watchdog.

use core::sync::atomic::Ordering;

use defmt::{error, info, warn};
use defmt_rtt as _;
use embassy_executor::Spawner;
use embassy_stm32::adc::{Adc, AdcConfig, Exten, SampleTime};
use embassy_stm32::can::{self, CanConfigurator};
use embassy_stm32::flash::{Blocking, Flash};
use embassy_stm32::interrupt::{InterruptExt, Priority};
use embassy_stm32::peripherals::FDCAN1;
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::complementary_pwm::{ComplementaryPwm, Mms2, Ossi, Ossr};
use embassy_stm32::timer::low_level::CountingMode;
use embassy_stm32::timer::Channel;
use embassy_stm32::wdg::IndependentWatchdog;
use embassy_stm32::{bind_interrupts, interrupt, Config};
use embassy_time::{Duration, Ticker, Timer};
use model_core::control::page::PAGE_BYTES;
use model_core::control::ConfigImage;
use model_core::protocol::{mode_code, Command, Nack, PageAssembler, Response, FRAME};

use crate::board::{self, Board};
use crate::controller::{self, Control, Loop, Snapshot};

bind_interrupts!(struct Irqs {
    FDCAN1_IT0 => can::IT0InterruptHandler<FDCAN1>;
    FDCAN1_IT1 => can::IT1InterruptHandler<FDCAN1>;
});

/// Clock tree: 16 MHz HSI / 4 × 85 = 340 MHz VCO, / 2 on PLL R = 170 MHz SYSCLK, with
/// range-1 boost mode (required above 150 MHz). AHB/APB1/APB2 undivided (170 MHz), so TIM1
/// counts at 170 MHz. For a board crystal, set `rcc.hse` and `PllSource::HSE` with a prediv
/// giving the same 4 MHz PLL input (e.g. 24 MHz HSE / 6).
fn clocks() -> Config {
    use embassy_stm32::rcc::{Pll, PllMul, PllPreDiv, PllRDiv, PllSource, Sysclk};
    let mut config = Config::default();
    config.rcc.hsi = true;
    config.rcc.pll = Some(Pll {
        source: PllSource::HSI,
        prediv: PllPreDiv::DIV4,
        mul: PllMul::MUL85,
        divp: None,
        divq: None,
        divr: Some(PllRDiv::DIV2),
    });
    config.rcc.sys = Sysclk::PLL1_R;
    config.rcc.boost = true;
    config
}

const CORE_HZ: u32 = 170_000_000;

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

/// The stored page, or the defaults when it is blank or invalid.
fn load_config(flash: &mut Flash<'static, Blocking>) -> (Loop, model_core::control::ValidatedConfig) {
    let mut buf = [0u8; PAGE_BYTES];
    let stored = match flash.blocking_read(board::CONFIG_PAGE_OFFSET, &mut buf) {
        Ok(()) => ConfigImage::decode(&buf).and_then(|img| Loop::from_image(&img).map(|lp| (lp, img.control))),
        Err(_) => Err(model_core::control::PageError::Malformed("flash read")),
    };
    match stored {
        Ok(c) => {
            info!("configuration page loaded");
            c
        }
        Err(e) => {
            warn!("configuration page not used ({}); compiled-in defaults", page_error(&e));
            match controller::default_image().and_then(|img| Loop::from_image(&img).map(|lp| (lp, img.control))) {
                Ok(c) => c,
                Err(e) => defmt::panic!("compiled-in configuration rejected: {}", page_error(&e)),
            }
        }
    }
}

#[embassy_executor::main]
async fn main(spawner: Spawner) {
    let p = embassy_stm32::init(clocks());
    let b = Board::new(p);
    info!("MR clutch controller, SYSCLK 170 MHz, control {} Hz", board::CONTROL_HZ);

    let mut cp = match cortex_m::Peripherals::take() {
        Some(cp) => cp,
        None => defmt::panic!("core peripherals taken"),
    };
    cp.DCB.enable_trace();
    cp.DWT.enable_cycle_counter();

    let mut flash = Flash::new_blocking(b.flash);
    let (lp, cfg) = load_config(&mut flash);

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
    // One update event per PWM period (at the counter underflow: the centre of the
    // high-side on-time), which is TRGO2 for the ADC.
    pwm.set_repetition_counter(1);
    pwm.set_mms2(Mms2::UPDATE);
    pwm.set_duty(Channel::Ch1, 0);
    pwm.set_duty(Channel::Ch2, 0);
    pwm.enable(Channel::Ch1);
    pwm.enable(Channel::Ch2);
    controller::safe_state();
    let max_duty = pwm.get_max_duty();
    info!("PWM: {} counts for duty 1 (config pwm_counts {})", max_duty, cfg.get().pwm_counts as u32);

    // ADC1 injected sequence started by TIM1 TRGO2, end-of-sequence interrupt.
    let adc = Adc::new(b.adc, AdcConfig::default());
    let adc = adc.setup_injected_conversions(
        [(b.hall, SampleTime::CYCLES12_5), (b.current, SampleTime::CYCLES12_5), (b.supply, SampleTime::CYCLES12_5)],
        embassy_stm32::triggers::TIM1_TRGO2,
        Exten::RISING_EDGE,
        true,
    );

    critical_section::with(|cs| {
        controller::CONTROL.borrow_ref_mut(cs).replace(Control {
            lp,
            cfg,
            pwm,
            adc,
            max_duty,
            period_cycles: CORE_HZ / board::CONTROL_HZ,
            overrun: false,
            driving: false,
        });
    });
    interrupt::ADC1_2.set_priority(Priority::P0);
    // SAFETY: the handler only touches `CONTROL`/`PENDING` inside critical sections and
    // the atomics; it is installed now that `CONTROL` holds the peripherals it drives.
    unsafe { interrupt::ADC1_2.enable() };

    let mut can = CanConfigurator::new(b.can, b.can_rx, b.can_tx, Irqs);
    can.set_bitrate(board::CAN_BITRATE);
    let can = can.into_normal_mode();

    let iwdg = IndependentWatchdog::new(b.iwdg, board::WATCHDOG_US);
    match (telemetry(), commands(can, flash), supervisor()) {
        (Ok(t), Ok(c), Ok(s)) => {
            spawner.spawn(t);
            spawner.spawn(c);
            spawner.spawn(s);
        }
        _ => defmt::panic!("spawning tasks"),
    }
    watchdog(iwdg).await;
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
        if now != last {
            iwdg.pet();
        } else {
            controller::safe_state();
            error!("control interrupt stalled: bridge off, watchdog will reset");
        }
        last = now;
    }
}

/// The slow supervisor pass of the control step at `SLOW_HZ` (configuration fingerprint
/// and time step; the step trips `SupervisorStalled` if this task stops).
#[embassy_executor::task]
async fn supervisor() {
    let mut ticker = Ticker::every(Duration::from_hz(controller::SLOW_HZ));
    loop {
        ticker.next().await;
        controller::slow_pass();
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

/// CAN commands (protocol in `model_core::protocol`).
#[embassy_executor::task]
async fn commands(mut can: embassy_stm32::can::Can<'static>, mut flash: Flash<'static, Blocking>) {
    let mut page = PageAssembler::default();
    loop {
        let env = match can.read().await {
            Ok(env) => env,
            Err(e) => {
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
        let data = env.frame.data();
        let code = data.first().copied().unwrap_or(0);
        let answer = match Command::decode(data) {
            Err(why) => Some(Response::Nack(code, why)),
            Ok(Command::SetTorque(t)) => {
                controller::REFERENCE.store(t.to_bits(), Ordering::Relaxed);
                None
            }
            Ok(Command::Enable(e)) => {
                controller::ENABLE.store(e, Ordering::Relaxed);
                Some(Response::Ack(code))
            }
            Ok(Command::Reset) => {
                controller::RESET.store(true, Ordering::Relaxed);
                Some(Response::Ack(code))
            }
            Ok(Command::GetStatus) => {
                let s = critical_section::with(|cs| controller::TELEMETRY.borrow(cs).get());
                let ovr = controller::OVERRUNS.load(Ordering::Relaxed).min(255) as u8;
                Some(Response::Status {
                    mode: mode_code(s.out.mode),
                    fault: s.out.fault.code(),
                    overruns: ovr,
                    torque_est: s.out.torque_est,
                })
            }
            Ok(Command::ConfigBegin { len }) => Some(match page.begin(len) {
                Ok(()) => Response::Ack(code),
                Err(why) => Response::Nack(code, why),
            }),
            Ok(Command::ConfigData { offset, len, data }) => page
                .data(offset, data.get(..usize::from(len)).unwrap_or(&[]))
                .err()
                .map(|why| Response::Nack(code, why)),
            Ok(Command::ConfigCommit { crc }) => Some(
                commit(&mut page, crc, &mut flash)
                    .map_or_else(|why| Response::Nack(code, why), |()| Response::Ack(code)),
            ),
        };
        if let Some(frame) = answer.and_then(reply) {
            can.write(&frame).await;
        }
    }
}

/// Validate the received page, write it to flash, hand it to the control interrupt.
fn commit(page: &mut PageAssembler, crc: u32, flash: &mut Flash<'static, Blocking>) -> Result<(), Nack> {
    if controller::ENABLE.load(Ordering::Relaxed) {
        return Err(Nack::Busy);
    }
    let (bytes, img) = page.commit(crc)?;
    let lp = Loop::from_image(&img).map_err(|_| Nack::InvalidPage)?;
    let from = board::CONFIG_PAGE_OFFSET;
    flash.blocking_erase(from, from + PAGE_BYTES as u32).map_err(|_| Nack::Flash)?;
    flash.blocking_write(from, bytes).map_err(|_| Nack::Flash)?;
    critical_section::with(|cs| controller::PENDING.borrow_ref_mut(cs).replace((lp, img.control)));
    info!("new configuration: model {}, written to flash", img.model_id());
    Ok(())
}
