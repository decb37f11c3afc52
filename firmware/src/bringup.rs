//! Board numbers and the checks a configuration must pass against this board before it
//! runs, the reset cause, and the compiled-in configuration.

use model_core::control::{ConfigImage, ControlConfig, LoopMode, PageError, RateSpec, ValidatedConfig};
use model_core::models::algebraic;
use model_core::Model;

/// PWM frequency and fastest control rate, Hz: TIM1 centre-aligned, at most one ADC
/// trigger per period.
pub const CONTROL_HZ: u32 = 20_000;
/// The control rates a page can run at, Hz (issue 17): the ADC trigger (TIM1's update
/// event) every 1, 2, 4, 10 or 20 PWM periods (the repetition counter), the PWM staying at
/// [`CONTROL_HZ`]. Each model's rate is chosen from these (`firmware::runner`).
pub const CONTROL_RATES: [u32; 5] = [20_000, 10_000, 5_000, 2_000, 1_000];

/// PWM periods per control period at `control_hz` (`None` off the menu).
pub fn pwm_periods_per_step(control_hz: u32) -> Option<u32> {
    CONTROL_RATES.contains(&control_hz).then(|| CONTROL_HZ / control_hz)
}
/// Core and timer clock, Hz.
pub const CORE_HZ: u32 = 170_000_000;
/// TIM1 counts for duty 1: centre-aligned, so half a period of core clocks (ARR + 1: a
/// compare of ARR + 1 keeps the output active through the whole period).
pub const PWM_COUNTS: u32 = CORE_HZ / CONTROL_HZ / 2;
/// ADC (and DAC) reference voltage, V, and full scale, counts.
pub const VREF: f32 = 3.3;
pub const FULL_SCALE: f32 = 4095.0;
/// Supply-sense divider: V at the bridge per V at the pin.
pub const SUPPLY_DIVIDER: f32 = 11.0;

/// Bridge supply, V, from its ADC counts (the same f32 operations as the interrupt).
#[inline(always)]
pub fn supply_volts(counts: u16) -> f32 {
    f32::from(counts) * (VREF / FULL_SCALE * SUPPLY_DIVIDER)
}

/// Why a configuration cannot run on this board.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum BoardMismatch {
    /// `pwm_counts` is not the timer's count for duty 1: `duty_max` would be applied on
    /// the wrong scale (larger: saturating at 100 %; smaller: never reaching duty_max).
    PwmCounts,
    /// `dt` is not one of this board's control periods ([`CONTROL_RATES`]).
    SamplePeriod,
    /// The over-current trip is beyond what the comparator's DAC can express.
    OverCurrentRange,
}

/// Check a validated configuration against the board: the timer's counts for duty 1,
/// the control period (one of [`CONTROL_RATES`]; whether it is the model's is
/// `firmware::runner`'s check), the comparator threshold.
pub fn check_board(cfg: &ValidatedConfig, timer_counts: u32) -> Result<u16, BoardMismatch> {
    let c = cfg.get();
    if c.pwm_counts != timer_counts as f32 {
        return Err(BoardMismatch::PwmCounts);
    }
    if rate_of_dt(c.dt).is_none() {
        return Err(BoardMismatch::SamplePeriod);
    }
    over_current_counts(c).ok_or(BoardMismatch::OverCurrentRange)
}

/// The menu rate ([`CONTROL_RATES`]) whose period is `dt` (within 1 ppm), if any.
pub fn rate_of_dt(dt: f32) -> Option<u32> {
    CONTROL_RATES.iter().copied().find(|&hz| {
        let p = 1.0 / hz as f32;
        (dt - p).abs() <= 1e-6 * p
    })
}

/// The comparator threshold (DAC counts, same reference as the ADC) for the configured
/// over-current trip: the current sense's offset plus `over_current / current_gain`.
/// The hardware trip is 1/8 above the software trip, so the software check (confirmed
/// over samples) acts first on a slow rise and the comparator on a short.
pub fn over_current_counts(c: &ControlConfig) -> Option<u16> {
    let counts = c.current_offset + 1.125 * c.over_current / c.current_gain;
    (counts.is_finite() && counts > c.current_offset && counts <= FULL_SCALE).then_some(counts as u16)
}

/// Why the chip last reset (RCC_CSR flags, RM0440 §7.4.29, highest priority first).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum ResetCause {
    LowPower,
    WindowWatchdog,
    IndependentWatchdog,
    Software,
    BrownOut,
    Pin,
    OptionByteLoad,
    Unknown,
}

impl ResetCause {
    /// From the RCC_CSR value (bits 25–31).
    pub const fn from_csr(csr: u32) -> Self {
        if csr & (1 << 31) != 0 {
            Self::LowPower
        } else if csr & (1 << 30) != 0 {
            Self::WindowWatchdog
        } else if csr & (1 << 29) != 0 {
            Self::IndependentWatchdog
        } else if csr & (1 << 28) != 0 {
            Self::Software
        } else if csr & (1 << 27) != 0 {
            Self::BrownOut
        } else if csr & (1 << 26) != 0 {
            Self::Pin
        } else if csr & (1 << 25) != 0 {
            Self::OptionByteLoad
        } else {
            Self::Unknown
        }
    }

    /// A cause the supervisor reports as a fault at start-up (the bridge was switching
    /// when the chip stopped).
    pub const fn is_fault(self) -> bool {
        matches!(self, Self::WindowWatchdog | Self::IndependentWatchdog | Self::LowPower)
    }
}

/// The compiled-in configuration, used when no slot holds a usable page: the algebraic
/// model (seed 000 eq. 14) in T with a placeholder set, torque mode, the 20 kHz defaults
/// of `ControlConfig`. The bridge stays off until a command enables it; load the clutch's
/// fitted set with `hil-sim export` (README).
pub fn default_image() -> Result<ConfigImage, PageError> {
    let dt = 1.0 / CONTROL_HZ as f32;
    let control =
        ControlConfig { mode: LoopMode::Torque, pwm_counts: PWM_COUNTS as f32, ..ControlConfig::defaults(dt) }
            .validate()
            .map_err(PageError::Invalid)?;
    ConfigImage::new(algebraic::Algebraic::ID, &[20.0, -0.05, -10.0, 0.8], RateSpec::Filtered { fc: 150.0 }, control)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cfg(f: impl FnOnce(&mut ControlConfig)) -> ValidatedConfig {
        let mut c = ControlConfig::defaults(1.0 / CONTROL_HZ as f32);
        f(&mut c);
        c.validate().expect("valid")
    }

    #[test]
    fn the_default_image_runs_on_this_board() {
        let img = default_image().expect("image");
        assert!(check_board(&img.control, PWM_COUNTS).is_ok());
    }

    #[test]
    fn pwm_counts_must_be_the_timers() {
        let big = cfg(|c| c.pwm_counts = 65535.0);
        assert_eq!(check_board(&big, PWM_COUNTS), Err(BoardMismatch::PwmCounts));
        let small = cfg(|c| c.pwm_counts = 1000.0);
        assert_eq!(check_board(&small, PWM_COUNTS), Err(BoardMismatch::PwmCounts));
    }

    #[test]
    fn a_control_rate_off_the_menu_is_refused() {
        for hz in CONTROL_RATES {
            assert_eq!(rate_of_dt(1.0 / hz as f32), Some(hz));
            assert_eq!(pwm_periods_per_step(hz).map(|n| n * hz), Some(CONTROL_HZ));
        }
        assert_eq!(pwm_periods_per_step(7_000), None);
        let mut c = ControlConfig::defaults(1.0 / 7_000.0);
        c.pwm_counts = PWM_COUNTS as f32;
        let v = c.validate().expect("valid");
        assert_eq!(check_board(&v, PWM_COUNTS), Err(BoardMismatch::SamplePeriod));
    }

    #[test]
    fn comparator_threshold_is_above_the_software_trip() {
        let c = cfg(|c| c.pwm_counts = PWM_COUNTS as f32);
        let k = check_board(&c, PWM_COUNTS).expect("fits");
        let soft = c.get().current_offset + c.get().over_current / c.get().current_gain;
        assert!(f32::from(k) > soft && f32::from(k) <= FULL_SCALE, "{k} vs {soft}");
        let huge = cfg(|c| {
            c.pwm_counts = PWM_COUNTS as f32;
            c.over_current = 900.0;
        });
        assert_eq!(check_board(&huge, PWM_COUNTS), Err(BoardMismatch::OverCurrentRange));
    }

    #[test]
    fn reset_cause_by_priority() {
        assert_eq!(ResetCause::from_csr(1 << 29 | 1 << 26), ResetCause::IndependentWatchdog);
        assert_eq!(ResetCause::from_csr(1 << 26), ResetCause::Pin);
        assert_eq!(ResetCause::from_csr(0), ResetCause::Unknown);
        assert!(ResetCause::IndependentWatchdog.is_fault());
        assert!(!ResetCause::Pin.is_fault());
    }

    #[test]
    fn zero_supply_reading_is_zero_volts() {
        assert_eq!(supply_volts(0), 0.0);
        assert!((supply_volts(4095) - 36.3).abs() < 1e-3);
    }
}
