//! The truth of a concealed-effect recording before any effect: the field `b_true(t)` (T)
//! from one of the excitations, the base model's torque (N·m) driven by it and its true
//! (zero-phase) rate, and the auxiliary channels every recording carries — the coil
//! current `i = (b + τ_e·ḃ + b_r·tanh(ḃ/ε))/k` (A), the slip speed (rad/s) and the
//! temperature heated by the slip power, `θ̇ = (g·|T·ω| − (θ − 25))/60 s` (°C).

use std::f64::consts::PI;

use model_core::models::{algebraic, bouc_wen, dahl, lugre, tanh};
use model_core::Model;
use rand::Rng;

use super::spec::{ConcealedError, ConcealedSpec};

/// Eddy-current time constant between coil current and field, s.
const TAU_EDDY_S: f64 = 0.002;
/// Remanence of the steel, T.
const B_REMANENT_T: f64 = 0.02;
/// Field per ampere, T/A.
const K_T_PER_A: f64 = 0.25;
/// Temperature rise over the recording the heating gain aims at, K (before the 1.2 margin).
const HEATING_K: f64 = 10.0;
/// Thermal time constant, s.
const THERMAL_TAU_S: f64 = 60.0;
/// Ambient and starting temperature, °C.
const AMBIENT_C: f64 = 25.0;

/// Clutch-like truth of each base (flux density in T, torque in N·m): each model fitted once
/// to `hil-sim simulate --scenario multisine` (`fit --delay off`), rounded.
const TRUTHS: [(&str, &[(&str, f64)]); 5] = [
    (algebraic::Registered::ID, &[("t0", 1.02), ("k", 29.3), ("alpha", -31.3), ("c", 0.02)]),
    (
        bouc_wen::Registered::ID,
        &[
            ("alpha", 9.03),
            ("beta", 26.0),
            ("gamma", 0.055),
            ("delta", 1.0),
            ("n", 2.0),
            ("c", 0.02),
            ("k", 20.1),
            ("x0", -0.117),
        ],
    ),
    (
        lugre::Registered::ID,
        &[("t0", 2.16), ("k", 24.5), ("alpha", 972.0), ("beta", 0.00292), ("epsilon", 0.0296), ("c", 0.02)],
    ),
    (
        tanh::Registered::ID,
        &[("t0", 1.93), ("k", 24.4), ("alpha", -0.297), ("beta", 1.21), ("gamma", -1.86), ("c", 0.02)],
    ),
    (
        dahl::Registered::ID,
        &[
            ("f0", -2.22),
            ("K0", 25.0),
            ("C0s", 0.000485),
            ("C0d", 0.0),
            ("Fds", 0.000217),
            ("Fdu", 0.0),
            ("sigma", 57000.0),
            ("eta", 190.0),
        ],
    ),
];

/// The truth of base `base` by parameter name; `None` for a model that is not a base.
pub fn truth(base: &str) -> Option<Vec<(&'static str, f64)>> {
    TRUTHS.iter().find(|(id, _)| *id == base).map(|(_, set)| set.to_vec())
}

/// The truth's flat parameter vector in the registry's order.
pub fn flat(base: &str) -> Option<Vec<f32>> {
    let info = model_core::registry::find(base)?;
    let named = truth(base)?;
    info.params.iter().map(|n| named.iter().find(|(k, _)| k == n).map(|(_, v)| *v as f32)).collect()
}

/// The excitation, normalised to [−1, 1].
fn excitation(name: &str, t: &[f64], duration: f64, rng: &mut impl Rng) -> Vec<f64> {
    let raw: Vec<f64> = match name {
        "multisine" | "bipolar" => {
            let f = [0.7, 1.3, 2.9, 4.1, 6.7, 9.3];
            let ph: Vec<f64> = f.iter().map(|_| 2.0 * PI * rng.random::<f64>()).collect();
            t.iter().map(|t| f.iter().zip(&ph).map(|(f, p)| (2.0 * PI * f * t + p).sin()).sum()).collect()
        }
        "noise" => {
            let comps: Vec<(f64, f64)> = (0..64)
                .map(|k| (0.2 + 14.8 * (k as f64 + rng.random::<f64>()) / 64.0, 2.0 * PI * rng.random::<f64>()))
                .collect();
            t.iter().map(|t| comps.iter().map(|(f, p)| (2.0 * PI * f * t + p).sin()).sum()).collect()
        }
        "sweep" => {
            let (f0, f1) = (0.5, 15.0);
            let k: f64 = f1 / f0;
            t.iter().map(|t| (2.0 * PI * f0 * duration / k.ln() * (k.powf(t / duration) - 1.0)).sin()).collect()
        }
        _ => {
            // Triangle at 1.5 Hz, its amplitude swept slowly so the loop visits every level.
            let ph = rng.random::<f64>();
            t.iter()
                .map(|t| {
                    let c = (1.5 * t + ph).fract();
                    let tri = if c < 0.5 { 4.0 * c - 1.0 } else { 3.0 - 4.0 * c };
                    tri * (0.65 + 0.35 * (2.0 * PI * 0.11 * t).sin())
                })
                .collect()
        }
    };
    let peak = raw.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(1e-12);
    raw.iter().map(|v| v / peak).collect()
}

/// Root-mean-square of `v`.
pub use crate::numerics::stats::rms;

/// The base model's torque for the field `b` the model sees (its true rate attached).
pub fn torque(base: &str, p: &[f32], b: &[f64], dt: f64) -> Result<Vec<f64>, ConcealedError> {
    let rates = crate::numerics::derivative::rates(b, dt);
    let samples = crate::models::replay::samples_with_rates(b, None, Some(&rates));
    let r = crate::models::replay(base, p, dt as f32, crate::models::RateSpec::Backward, &samples)
        .map_err(|_| ConcealedError::Diverged(base.to_owned()))?;
    if r.held > 0 {
        return Err(ConcealedError::Diverged(base.to_owned()));
    }
    Ok(r.y.iter().map(|v| f64::from(*v)).collect())
}

/// The true signals of one recording.
pub struct Truth {
    pub dt: f64,
    /// Time (s), the true field (T) and its zero-phase rate (T/s).
    pub t: Vec<f64>,
    pub b: Vec<f64>,
    pub db: Vec<f64>,
    /// Standard deviation of the rate, largest and mean field.
    pub db_std: f64,
    pub b_max: f64,
    pub b_mean: f64,
    /// Coil current (A), slip speed (rad/s) and its rate, temperature (°C).
    pub i: Vec<f64>,
    pub speed: Vec<f64>,
    pub domega: Vec<f64>,
    pub temperature: Vec<f64>,
    /// The base model's torque (N·m) and its span (peak to peak).
    pub base: Vec<f64>,
    pub span: f64,
}

impl Truth {
    /// The truth of `spec` (`n` samples of `dt`) with base parameters `p`; draws the
    /// excitation's and the speed's phases from `rng`.
    pub fn new(spec: &ConcealedSpec, p: &[f32], n: usize, dt: f64, rng: &mut impl Rng) -> Result<Self, ConcealedError> {
        let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        let s = excitation(&spec.excitation, &t, spec.duration_s, rng);
        // `bipolar`: the multi-sine through zero (an H-bridge driving the coil both ways),
        // where a zero offset of the Hall reading shows as a kink away from zero.
        let b: Vec<f64> =
            s.iter().map(|s| if spec.excitation == "bipolar" { 0.5 * s } else { 0.325 + 0.275 * s }).collect();
        let (db, _) = crate::numerics::derivative::rates(&b, dt);
        let db_mean = db.iter().sum::<f64>() / n as f64;
        let db_std = rms(&db.iter().map(|v| v - db_mean).collect::<Vec<_>>()).max(1e-12);
        let b_max = b.iter().fold(0.0f64, |a, v| a.max(*v));
        let b_mean = b.iter().sum::<f64>() / n as f64;
        let i: Vec<f64> = b
            .iter()
            .zip(&db)
            .map(|(b, d)| (b + TAU_EDDY_S * d + B_REMANENT_T * (d / (0.1 * db_std)).tanh()) / K_T_PER_A)
            .collect();
        let speed = slip_speed(&t, rng);
        let domega = crate::numerics::derivative::rates(&speed, dt).0;
        let base = torque(&spec.base, p, &b, dt)?;
        let (lo, hi) = base.iter().fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
        let span = (hi - lo).max(1e-9);
        let temperature = heating(&base, &speed, spec.duration_s, dt);
        Ok(Self { dt, t, b, db, db_std, b_max, b_mean, i, speed, domega, temperature, base, span })
    }
}

/// The slip speed, rad/s: 20 rad/s with slow (0.07 Hz, 0.31 Hz) and 2.3 Hz variations,
/// independent of the field.
fn slip_speed(t: &[f64], rng: &mut impl Rng) -> Vec<f64> {
    let ph: Vec<f64> = (0..3).map(|_| 2.0 * PI * rng.random::<f64>()).collect();
    t.iter()
        .map(|t| {
            20.0 + 4.0 * (2.0 * PI * 0.07 * t + ph[0]).sin()
                + 2.0 * (2.0 * PI * 0.31 * t + ph[1]).sin()
                + 1.5 * (2.0 * PI * 2.3 * t + ph[2]).sin()
        })
        .collect()
}

/// The temperature, °C: a first-order state heated by the slip power `|T·ω|` of the base
/// torque, its gain set for about [`HEATING_K`] of rise over the recording.
fn heating(torque: &[f64], speed: &[f64], duration_s: f64, dt: f64) -> Vec<f64> {
    let power: Vec<f64> = torque.iter().zip(speed).map(|(t, w)| (t * w).abs()).collect();
    let mean_power = power.iter().sum::<f64>() / power.len() as f64;
    let gain = HEATING_K / (mean_power.max(1e-9) * duration_s) * 1.2;
    let mut theta = AMBIENT_C;
    power
        .iter()
        .map(|p| {
            theta += dt * (gain * THERMAL_TAU_S * p - (theta - AMBIENT_C)) / THERMAL_TAU_S;
            theta
        })
        .collect()
}
