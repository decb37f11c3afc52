//! Torque references of the `loop` scenarios, N·m as functions of the time since the
//! reference started (s).

use crate::sim::excitation::Excitation;

/// The multisine torque reference of the `multisine` scenario: seed 000 eq. 21 mapped to
/// 6 ± 4 N·m (2–10 N·m).
pub fn multisine_reference() -> impl Fn(f64) -> f64 {
    let ms = Excitation::seed000_multisine();
    move |t: f64| 6.0 + 4.0 * ms.at(t).x
}

/// Levels of the `steps` scenario, N·m, held [`STEP_S`] each.
pub const STEP_LEVELS: [f64; 6] = [2.0, 8.0, 4.0, 10.0, 0.0, 6.0];
/// Hold time of each step level, s.
pub const STEP_S: f64 = 0.25;

/// Torque steps 2 → 8 → 4 → 10 → 0 → 6 N·m, [`STEP_S`] each (the last held).
pub fn steps_reference(t: f64) -> f64 {
    STEP_LEVELS[((t / STEP_S) as usize).min(STEP_LEVELS.len() - 1)]
}

/// `mean + amp·sin(2π·f·t)`.
pub fn sine_reference(mean: f64, amp: f64, f: f64) -> impl Fn(f64) -> f64 {
    move |t: f64| mean + amp * (2.0 * std::f64::consts::PI * f * t).sin()
}
