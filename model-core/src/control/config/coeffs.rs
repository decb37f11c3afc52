//! The coefficients of the per-sample step, pre-computed from validated settings: integral
//! gains times `dt`, reciprocals, limits as integer sample counts (module docs of
//! [`config`](super)).

use super::{ControlConfig, LoopMode};

/// What the per-sample step reads, pre-computed once from a validated [`ControlConfig`]
/// ([`Coeffs::new`]; the slow supervisor re-computes it and compares). Units as in
/// [`ControlConfig`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coeffs {
    pub mode: LoopMode,
    /// T per count, A per count.
    pub hall_gain: f32,
    pub current_gain: f32,
    /// Hall counts in range: `hall − rail_base < rail_span` (wrapping, u32), i.e.
    /// `hall_rail_lo < hall < hall_rail_hi`.
    pub rail_base: u32,
    pub rail_span: u32,
    /// Hall counts at or above this are the upper rail (`⌈hall_rail_hi⌉`).
    pub rail_hi: u32,
    /// Over-current trip, A; supply window, V.
    pub over_current: f32,
    pub v_min: f32,
    pub v_max: f32,
    /// Consecutive samples a fast condition (rail, over-current, supply, overrun, model)
    /// must persist.
    pub confirm: u32,
    /// Samples of the slow-developing checks (`u32::MAX`: disabled).
    pub stuck_n: u32,
    pub open_n: u32,
    pub band_n: u32,
    /// Reversing Hall jumps within 8 samples that trip the noise check.
    pub slew_n: u32,
    /// Largest plausible Hall change per sample in counts (`b_slew_max/hall_gain`).
    pub slew_counts: u32,
    /// Coil-open check: V, A.
    pub open_v: f32,
    pub open_i: f32,
    /// Plausibility band, T (`+∞`: disabled), and the B/i slope, T/A.
    pub b_band: f32,
    pub b_per_amp: f32,
    /// `1/b_per_amp`, A/T; the feed-forward's lead per torque-loop update (two samples),
    /// `ff_lead_s/(2·dt)` (1).
    pub amp_per_b: f32,
    pub lead: f32,
    /// Feed-forward: the range of B* (`[0, b_max − h]`, T), the forward-difference width
    /// `h = 10⁻³·b_max` (T), the largest Newton step (T).
    pub ff_hi: f32,
    pub ff_h: f32,
    pub ff_step: f32,
    /// Reference limit (N·m, or A in current mode) and the current limit, A.
    pub ref_lim: f32,
    pub i_max: f32,
    /// Torque PI: A/(N·m), A/(N·m) per update (the torque loop runs every second sample:
    /// `ki_t·2·dt`); current PI: V/A, V/A per sample.
    pub kp_t: f32,
    pub ki_t_dt: f32,
    pub kp_i: f32,
    pub ki_i_dt: f32,
    /// Coil resistance, Ω.
    pub coil_r: f32,
    /// Largest |duty|, PWM counts for duty 1.
    pub duty_max: f32,
    pub pwm_counts: f32,
    /// Demagnetising pulse: duty, samples, arming threshold.
    pub demag_duty: f32,
    pub demag_samples: u16,
    pub demag_threshold: f32,
    /// Samples without a slow-supervisor pass before the step trips
    /// [`FaultCode::SupervisorStalled`](crate::control::FaultCode::SupervisorStalled) (0.1 s).
    pub slow_timeout: u32,
}

/// The slow supervisor must pass at least this often (s).
pub const SLOW_TIMEOUT_S: f32 = 0.1;

impl Coeffs {
    /// Pre-compute from settings that passed [`ControlConfig::validate`].
    pub fn new(c: &ControlConfig) -> Self {
        let count = |n: f32| if n > 0.0 { n as u32 } else { 0 };
        let rail_lo = libm::floorf(c.hall_rail_lo) as u32;
        let rail_hi = libm::ceilf(c.hall_rail_hi) as u32;
        let h = 1e-3 * c.b_max;
        Self {
            mode: c.mode,
            hall_gain: c.hall_gain,
            current_gain: c.current_gain,
            rail_base: rail_lo.saturating_add(1),
            rail_span: rail_hi.saturating_sub(rail_lo.saturating_add(1)),
            rail_hi,
            over_current: c.over_current,
            v_min: c.v_min,
            v_max: c.v_max,
            confirm: count(c.confirm_samples),
            stuck_n: if c.stuck_samples > 0.0 { count(c.stuck_samples) } else { u32::MAX },
            open_n: count(c.open_samples),
            band_n: count(c.band_samples),
            slew_n: count(c.slew_count),
            slew_counts: (c.b_slew_max / c.hall_gain) as u32,
            open_v: c.open_v,
            open_i: c.open_i,
            b_band: if c.b_band > 0.0 { c.b_band } else { f32::INFINITY },
            b_per_amp: c.b_per_amp,
            amp_per_b: 1.0 / c.b_per_amp,
            lead: c.ff_lead_s / (2.0 * c.dt),
            ff_hi: c.b_max - h,
            ff_h: h,
            ff_step: 0.25 * c.b_max,
            ref_lim: if c.mode == LoopMode::Current { c.i_max } else { c.torque_max },
            i_max: c.i_max,
            kp_t: c.kp_t,
            ki_t_dt: c.ki_t * (2.0 * c.dt),
            kp_i: c.kp_i,
            ki_i_dt: c.ki_i * c.dt,
            coil_r: c.coil_r,
            duty_max: c.duty_max,
            pwm_counts: c.pwm_counts,
            demag_duty: c.demag_duty,
            demag_samples: count(c.demag_samples).min(u32::from(u16::MAX)) as u16,
            demag_threshold: c.demag_threshold,
            slow_timeout: count(libm::ceilf(SLOW_TIMEOUT_S / c.dt)),
        }
    }
}
