//! The board: which pins, timer, ADC channels and CAN port the application uses, and the
//! analog front end's scale factors. Reference wiring: a Nucleo-G474RE with an H-bridge
//! power stage (two half-bridges with gate drivers taking complementary inputs), a Hall
//! sensor front end, a coil-current sense amplifier and a CAN transceiver (table in the
//! README). Another STM32G4 board is a change of this file only.

use embassy_stm32::adc::{AdcChannel, AnyAdcChannel};
use embassy_stm32::peripherals::{ADC1, FDCAN1, FLASH, IWDG, PA11, PA12, TIM1};
use embassy_stm32::timer::complementary_pwm::ComplementaryPwmPin;
use embassy_stm32::timer::simple_pwm::PwmPin;
use embassy_stm32::timer::{Ch1, Ch2};
use embassy_stm32::{Peri, Peripherals};

/// Control (and PWM) frequency, Hz: TIM1 centre-aligned, one ADC trigger per period.
pub const CONTROL_HZ: u32 = 20_000;
/// Dead time of the bridge, TIM1 DTG value (see RM0440 §28.6.20: ≤ 127 → that many
/// 170 MHz ticks): 85 ticks = 500 ns, for gate drivers with ~200 ns propagation skew.
pub const DEAD_TIME_DTG: u16 = 85;
/// ADC reference voltage, V, and the supply-sense divider (V at the bridge per V at the pin).
pub const VREF: f32 = 3.3;
pub const SUPPLY_DIVIDER: f32 = 11.0;
/// CAN bit rate and identifiers: commands to `CAN_ID_CMD`, replies from `CAN_ID_REPLY`.
pub const CAN_BITRATE: u32 = 1_000_000;
pub const CAN_ID_CMD: u16 = 0x120;
pub const CAN_ID_REPLY: u16 = 0x121;
/// The configuration page: the last 2 KiB page of bank 2 (offset from the flash base;
/// `memory.x` keeps the linker out of it).
pub const CONFIG_PAGE_OFFSET: u32 = 0x7_F800;
/// Independent watchdog timeout, µs.
pub const WATCHDOG_US: u32 = 50_000;

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
    pub flash: Peri<'static, FLASH>,
    pub iwdg: Peri<'static, IWDG>,
}

impl Board {
    /// Nucleo-G474RE: TIM1 CH1/CH1N on PA8/PB13, CH2/CH2N on PA9/PB14 (the ST motor-control
    /// connector pins); Hall on PA0 (ADC1_IN1), coil current on PA1 (ADC1_IN2), supply on
    /// PB1 (ADC1_IN12); FDCAN1 on PA11/PA12.
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
        }
    }
}
