//! Controller settings: what a firmware engineer derives from the clutch's data-sheet
//! values (nominal sensor gains, coil R and L), the identified B/i slope (T/A) and the
//! identified algebraic model (seed 000 eq. 14). Current loop: PI zero on the coil pole,
//! 300 Hz crossover; torque loop: integral-dominant PI, 20 Hz crossover.

use model_core::control::{ControlConfig, ControlStep, LoopMode, ValidatedConfig};
use model_core::models::algebraic::Algebraic;
use model_core::rate::RateParams;

use super::error::LoopError;
use crate::sim::plant::ClutchParams;

/// Cut-off of the controller's rate estimator (filtered difference), Hz.
pub const RATE_FC_HZ: f32 = 150.0;

/// A current-mode controller (the current driver) at `control_hz`.
pub fn current_driver(
    clutch: &ClutchParams,
    control_hz: f64,
) -> Result<(ControlStep<Algebraic>, ValidatedConfig), LoopError> {
    let dt = (1.0 / control_hz) as f32;
    let placeholder = Algebraic::new(0.0, 0.0, 0.0, 0.0, dt)?;
    let step = ControlStep::new(placeholder, RateParams::filtered(dt, RATE_FC_HZ)?)?;
    let cfg = ControlConfig { mode: LoopMode::Current, ..base_config(clutch, dt, 0.2) };
    Ok((step, cfg.validate()?))
}

/// Settings a firmware engineer derives from the clutch's data sheet values (nominal
/// sensor gains, coil R and L) and the identified B/i slope.
pub fn base_config(clutch: &ClutchParams, dt: f32, b_per_amp: f32) -> ControlConfig {
    let s = &clutch.sensors;
    let c = &clutch.coil;
    // Current loop: PI zero on the coil pole, crossover 300 Hz (≪ 10 kHz loop rate).
    let wc = 2.0 * std::f64::consts::PI * 300.0;
    ControlConfig {
        hall_gain: (1.0 / s.hall_counts_per_t()) as f32,
        current_gain: (1.0 / s.current_counts_per_a()) as f32,
        calib_samples: (0.1 / f64::from(dt)).round() as f32,
        coil_r: c.r20 as f32,
        b_per_amp,
        kp_i: (c.l * wc) as f32,
        ki_i: (c.r20 * wc) as f32,
        v_min: (0.75 * c.supply_v) as f32,
        v_max: (1.25 * c.supply_v) as f32,
        // 16 identical counts in a row never happen with ≥ 1 count of sensor noise.
        stuck_samples: if s.noise { 16.0 } else { 0.0 },
        ..ControlConfig::defaults(dt)
    }
}

/// Torque-mode settings from the algebraic model `[k, c, alpha, t0]`, the B/i slope (T/A)
/// and the baseline's static map `[a0, a1, a2, a3]`.
pub fn torque_config(
    clutch: &ClutchParams,
    dt: f32,
    algebraic: [f32; 4],
    b_per_amp: f32,
    map: [f32; 4],
) -> ControlConfig {
    let [k, c, _, _] = algebraic;
    // Torque loop: the plant from current reference to torque estimate is ≈ K = k·B/i
    // (N·m/A) behind the current loop and the Hall lag; an integral-dominant PI with a
    // 20 Hz crossover (the estimate carries the model's lag −c/k ≈ 3 ms, so a faster
    // integral action peaks), and the feed-forward lead equal to that lag.
    let gain = (k * b_per_amp).max(1e-3);
    let wt = 2.0 * std::f32::consts::PI * 20.0;
    ControlConfig {
        mode: LoopMode::Torque,
        kp_t: 0.1 / gain,
        ki_t: wt / gain,
        ff_lead_s: (-c / k).clamp(0.0, 0.02),
        b_max: (clutch.magnetic.b_sat * 0.95) as f32,
        map,
        ..base_config(clutch, dt, b_per_amp)
    }
}
