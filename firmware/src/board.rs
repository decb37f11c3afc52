//! The board: which pins, timer, ADC channels and CAN port the application uses, and every
//! register access outside the HAL's drivers (flash slots, the comparator trip into TIM1's
//! break, the debug freeze, the reset cause). Reference wiring: a Nucleo-G474RE with an
//! H-bridge power stage (two half-bridges with gate drivers taking complementary inputs),
//! a Hall sensor front end, a coil-current sense amplifier and a CAN transceiver (table and
//! bring-up checklist in the README). Another STM32G4 board is a change of this file only.

use embassy_stm32::adc::{AdcChannel, AnyAdcChannel};
use embassy_stm32::pac;
use embassy_stm32::peripherals::{ADC1, FDCAN1, FLASH, IWDG, LPUART1, PA11, PA12, PA2, PA3, TIM1};
use embassy_stm32::timer::complementary_pwm::ComplementaryPwmPin;
use embassy_stm32::timer::simple_pwm::PwmPin;
use embassy_stm32::timer::{Ch1, Ch2};
use embassy_stm32::{Peri, Peripherals};
use firmware::bringup::ResetCause;
pub use firmware::bringup::{CONTROL_HZ, CORE_HZ, PWM_COUNTS};

pub mod flash;
pub mod ports;

/// Dead time of the bridge, TIM1 DTG value (see RM0440 §28.6.20: ≤ 127 → that many
/// 170 MHz ticks): 85 ticks = 500 ns, for gate drivers with ~200 ns propagation skew.
pub const DEAD_TIME_DTG: u16 = 85;
/// The Nucleo-G474RE's crystal (X3), Hz: the PLL input and FDCAN's kernel clock.
pub const HSE_HZ: u32 = 24_000_000;
/// CAN bit rate, bit/s.
pub const CAN_BITRATE: u32 = 1_000_000;
/// Commands arrive on this identifier (the acceptance filter's), replies leave from
/// `firmware::application::can::ID_REPLY`.
pub use firmware::application::can::ID_CMD as CAN_ID_CMD;
/// The serial link's baud rate (`hil-sim board --port /dev/ttyACM0` uses the same).
pub use firmware::application::serial::BAUD as UART_BAUD;
/// Independent watchdog timeout, µs (the virtual board models the same).
pub use firmware::application::watchdog::TIMEOUT_US as WATCHDOG_US;

/// Everything the application takes from the chip.
pub struct Board {
    pub tim1: Peri<'static, TIM1>,
    /// Half-bridge A (high side CH1, low side CH1N) and B (CH2, CH2N).
    pub bridge_a: (PwmPin<'static, TIM1, Ch1>, ComplementaryPwmPin<'static, TIM1, Ch1>),
    pub bridge_b: (PwmPin<'static, TIM1, Ch2>, ComplementaryPwmPin<'static, TIM1, Ch2>),
    pub adc: Peri<'static, ADC1>,
    /// Injected ranks, in this order: Hall sensor, coil current, bridge supply.
    pub hall: AnyAdcChannel<'static, ADC1>,
    pub current: AnyAdcChannel<'static, ADC1>,
    pub supply: AnyAdcChannel<'static, ADC1>,
    pub can: Peri<'static, FDCAN1>,
    pub can_rx: Peri<'static, PA11>,
    pub can_tx: Peri<'static, PA12>,
    /// Owned so nothing else programs the flash ([`flash`] does, by register).
    pub flash: Peri<'static, FLASH>,
    pub iwdg: Peri<'static, IWDG>,
    /// LPUART1 on the ST-LINK virtual COM port: PA2 TX, PA3 RX (the serial link).
    pub uart: Peri<'static, LPUART1>,
    pub uart_tx: Peri<'static, PA2>,
    pub uart_rx: Peri<'static, PA3>,
}

impl Board {
    /// Nucleo-G474RE: TIM1 CH1/CH1N on PA8/PB13, CH2/CH2N on PA9/PB14 (the ST motor-control
    /// connector pins); Hall on PA0 (ADC1_IN1), coil current on PA1 (ADC1_IN2, also
    /// COMP1_INP for the hardware trip), supply on PB1 (ADC1_IN12); FDCAN1 on PA11/PA12;
    /// LPUART1 on PA2/PA3 (the ST-LINK virtual COM port).
    pub fn new(p: Peripherals) -> Self {
        use embassy_stm32::gpio::OutputType::PushPull;
        Self {
            tim1: p.TIM1,
            bridge_a: (PwmPin::new(p.PA8, PushPull), ComplementaryPwmPin::new(p.PB13, PushPull)),
            bridge_b: (PwmPin::new(p.PA9, PushPull), ComplementaryPwmPin::new(p.PB14, PushPull)),
            adc: p.ADC1,
            hall: p.PA0.degrade_adc(),
            current: p.PA1.degrade_adc(),
            supply: p.PB1.degrade_adc(),
            can: p.FDCAN1,
            can_rx: p.PA11,
            can_tx: p.PA12,
            flash: p.FLASH,
            iwdg: p.IWDG,
            uart: p.LPUART1,
            uart_tx: p.PA2,
            uart_rx: p.PA3,
        }
    }
}

/// The reset cause (RCC_CSR), then its flags cleared (RMVF) so the next reset reads fresh.
pub fn reset_cause() -> ResetCause {
    let csr = pac::RCC.csr().read().0;
    pac::RCC.csr().modify(|w| w.set_rmvf(true));
    ResetCause::from_csr(csr)
}

/// The independent watchdog keeps counting while a debugger halts the core (RM0440
/// §46.2.4) unless DBGMCU freezes it: a breakpoint would reset the board.
pub fn freeze_watchdog_in_debug() {
    pac::DBGMCU.apb1lfzr().modify(|w| w.set_iwdg(true));
}

// Registers the PAC names differently per chip version; addresses and bits from RM0440.
const RCC_AHB2ENR: usize = 0x4002_104C;
const RCC_AHB2ENR_DAC3EN: u32 = 1 << 18;
const RCC_APB2ENR: usize = 0x4002_1060;
const RCC_APB2ENR_SYSCFGEN: u32 = 1 << 0;
const DAC3: usize = 0x5000_1000;
const DAC_CR: usize = 0x00;
const DAC_DHR12R1: usize = 0x08;
const DAC_MCR: usize = 0x3C;
/// MODE1 = 0b011: normal mode, internal connection only (COMP), buffer off; HFSEL = 0b10
/// for an AHB clock above 160 MHz.
const DAC_MCR_VALUE: u32 = 0b011 | (0b10 << 14);
const COMP1_CSR: usize = 0x4001_0200;
/// EN, INMSEL = DAC3_CH1 (0b100), INPSEL = PA1 (0), POL non-inverted, no hysteresis,
/// no blanking.
const COMP1_CSR_VALUE: u32 = 1 | (0b100 << 4);
const COMP_CSR_LOCK: u32 = 1 << 31;
const SYSCFG_CFGR2: usize = 0x4001_001C;
/// CLL (core lockup), SPL (SRAM parity), PVDL (PVD), ECCL (flash ECC double error) linked
/// to the timers' system break.
const SYSCFG_CFGR2_LINKS: u32 = 0b1111;
const TIM1_AF1: usize = 0x4001_2C60;
/// BKINE = 0 (no break pin), BKCMP1E: COMP1's output is a break source.
const TIM1_AF1_BKCMP1E: u32 = 1 << 1;

fn rmw(addr: usize, set: u32) {
    // SAFETY: `addr` is one of the RM0440 register addresses above, word-aligned, and only
    // this module writes these registers.
    unsafe {
        let p = addr as *mut u32;
        p.write_volatile(p.read_volatile() | set);
    }
}

fn write(addr: usize, value: u32) {
    // SAFETY: as in `rmw`.
    unsafe { (addr as *mut u32).write_volatile(value) }
}

/// The hardware over-current trip: DAC3 channel 1 at `threshold` counts on COMP1's
/// inverting input, the coil-current sense (PA1) on its non-inverting input, COMP1's
/// output into TIM1's break (active high, BKF filter 4 samples at f_DTS), plus the chip's
/// own fault sources (core lockup, SRAM parity, PVD, flash ECC) as system break. A break
/// clears MOE in hardware within a few tens of ns; AOE stays 0, so only software (after a
/// fault reset) sets MOE again. Called before the bridge is first enabled, with the
/// threshold from the configuration ([`firmware::bringup::over_current_counts`]).
pub fn arm_break(threshold: u16) {
    rmw(RCC_AHB2ENR, RCC_AHB2ENR_DAC3EN);
    rmw(RCC_APB2ENR, RCC_APB2ENR_SYSCFGEN);
    write(DAC3 + DAC_MCR, DAC_MCR_VALUE);
    write(DAC3 + DAC_DHR12R1, u32::from(threshold.min(4095)));
    write(DAC3 + DAC_CR, 1);
    write(COMP1_CSR, COMP1_CSR_VALUE);
    write(COMP1_CSR, COMP1_CSR_VALUE | COMP_CSR_LOCK);
    rmw(SYSCFG_CFGR2, SYSCFG_CFGR2_LINKS);
    rmw(TIM1_AF1, TIM1_AF1_BKCMP1E);
    pac::TIM1.bdtr().modify(|w| {
        w.set_bkf(0, pac::timer::vals::FilterValue::FCK_INT_N4);
        w.set_bkp(0, pac::timer::vals::Bkp::ACTIVE_HIGH);
        w.set_bke(0, true);
    });
    // Clear a break latched while arming.
    pac::TIM1.sr().modify(|w| w.set_bif(0, false));
}

/// Lock TIM1's break and dead-time configuration (BDTR LOCK level 1: DTG, BKE, BKP, AOE,
/// OISx; RM0440 §28.6.20) until the next reset. MOE stays writable.
pub fn lock_bridge_config() {
    pac::TIM1.bdtr().modify(|w| w.set_lock(pac::timer::vals::Lock::LEVEL1));
}

/// The bridge's safe state: main output enable off, so every switch takes its idle state
/// (off; OSSI set at start-up) and the coil current decays through the body diodes, and
/// both compares zero so a later enable starts from duty 0. Register writes through the
/// PAC so that the panic and fault handlers can call it whatever the rest of the program
/// holds.
#[inline(always)]
pub fn safe_state() {
    pac::TIM1.bdtr().modify(|w| w.set_moe(false));
    pac::TIM1.ccr(0).write(|w| w.set_ccr(0));
    pac::TIM1.ccr(1).write(|w| w.set_ccr(0));
}

/// TIM1's update interrupt (once per PWM period, the deadline monitor): enable it and
/// clear its flag.
pub fn enable_update_interrupt() {
    pac::TIM1.sr().modify(|w| w.set_uif(false));
    pac::TIM1.dier().modify(|w| w.set_uie(true));
}

/// Clear TIM1's update flag (in the deadline monitor).
#[inline(always)]
pub fn clear_update_flag() {
    pac::TIM1.sr().write(|w| {
        w.0 = !0;
        w.set_uif(false);
    });
}

/// Write the two compare registers (preloaded: they take effect at the next update).
#[inline(always)]
pub fn set_compares(a: u32, b: u32) {
    pac::TIM1.ccr(0).write(|w| w.set_ccr(a as u16));
    pac::TIM1.ccr(1).write(|w| w.set_ccr(b as u16));
}

/// Main output enable on.
#[inline(always)]
pub fn moe_on() {
    pac::TIM1.bdtr().modify(|w| w.set_moe(true));
}

/// TIM1's repetition count for one update event (ADC trigger, control interrupt) per
/// control period at `control_hz` (a [`firmware::bringup::CONTROL_RATES`] rate; the
/// fastest otherwise): centre-aligned, two counter turns per PWM period, so `2 n − 1` for
/// one event every `n` PWM periods, always at the underflow.
pub fn repetition_for(control_hz: u32) -> u8 {
    let n = firmware::bringup::pwm_periods_per_step(control_hz).unwrap_or(1);
    u8::try_from(2 * n - 1).unwrap_or(1)
}

/// Set TIM1's repetition count (a new control rate): RCR is preloaded, so the count in
/// progress ends as it was and the new one starts at the next update event (still at an
/// underflow: both counts are odd).
pub fn set_repetition(rep: u8) {
    pac::TIM1.rcr().write(|w| w.set_rep(u16::from(rep)));
}

/// Make TIM1's update event (TRGO2, the ADC trigger) come once per period at the counter
/// underflow, independent of what the HAL's calls did: counter stopped, at 0, counting up,
/// repetition counter `rep` loaded by a UG event (with URS set so UG itself raises no
/// update interrupt), counter started. In centre-aligned mode an odd repetition count
/// otherwise lands on the overflow or the underflow depending on when it was loaded.
pub fn align_update(rep: u8) {
    let t = pac::TIM1;
    t.cr1().modify(|w| w.set_cen(false));
    t.cnt().write(|w| w.set_cnt(0));
    t.rcr().write(|w| w.set_rep(u16::from(rep)));
    t.cr1().modify(|w| w.set_urs(pac::timer::vals::Urs::COUNTER_ONLY));
    t.egr().write(|w| w.set_ug(true));
    t.sr().modify(|w| w.set_uif(false));
    t.cr1().modify(|w| w.set_cen(true));
}
