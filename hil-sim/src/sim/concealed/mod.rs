//! Recordings with one concealed effect of the missing-physics catalog
//! (shared/spec/physics-catalog.md), for proving `hil-sim diagnose` blind.
//!
//! **Truth.** The field `b_true(t)` (T, 0.05–0.6 T; ±0.5 T for `bipolar`) follows one of
//! [`EXCITATIONS`]; the torque
//! is one of model-core's models ([`BASES`], a clutch-like parameter set fitted once on
//! `hil-sim simulate --scenario multisine`, see [`truth`]) driven by `b_true` and its true
//! (zero-phase) rate. Every recording carries the same auxiliary channels, effect or not:
//!
//! - `i` (A): the coil current, `i = (b + τ_e·ḃ + b_r·tanh(ḃ/ε))/k` — eddy currents
//!   (τ_e = 2 ms) and the steel's remanence (b_r = 0.02 T) make it more than a copy of `b`;
//! - `speed` (rad/s): the slip speed, 20 rad/s with slow and 2.3 Hz variations, independent
//!   of the field;
//! - `temperature` (°C): a first-order heating state θ̇ = (g·|T·ω| − (θ − 25))/60 s, from 25 °C
//!   up about 10 K over the recording.
//!
//! **The effect** (one, or `none`), with its strength set so that the RMS of what it changes
//! in the torque is `size` × the torque's span (peak to peak):
//!
//! | effect | the truth | label params |
//! | --- | --- | --- |
//! | `field_lag` | the model sees `b_f`, τ·ḃ_f = b − b_f | `tau_s` |
//! | `transport_delay` | the model sees `b(t − d)` | `delay_s` |
//! | `saturation` | the model sees `b_s·tanh(b/b_s)` | `b_sat_t` |
//! | `sensor_offset` | the recorded `b` reads `b + b_0` | `offset_t` |
//! | `rate_dependence` | `T += c·|ḃ|·ḃ` | `c_rate` (N·m·s²/T²) |
//! | `asymmetry` | `T += δ·(b − b̄)·tanh(ḃ/ε)` | `delta_nm_per_t` |
//! | `thermal_drift` | `T ×= 1 − κ·(θ − θ_0)` | `kappa_per_k` |
//! | `slip_speed` | `T += c_ω·ω·b/b_max` | `c_omega_nms` |
//! | `inertia` | `T += J·ω̇` (output rotor seen by the torque sensor) | `j_kgm2` |
//! | `aux_dependence` | `T ×= 1 + α·(i − ī)/i_span` | `alpha` |
//!
//! **Measurement chain** (every recording): `b`, `torque`, `i` and `speed` through the lab's
//! first-order 200 Hz anti-alias filter (the same on every channel, so `none` has no delay
//! between channels); `b` on a 12-bit ADC over ±1.25 T with 1 count of noise (as
//! [`crate::plant::sensors`]); `i` on a 12-bit ADC over ±6 A, 1 count; the torque with
//! white noise of 0.5 % of its span, then a 16-bit quantiser over its range; the temperature
//! with 0.1 K of noise. The label (which effect, its true values) goes to a separate file.

use std::collections::BTreeMap;
use std::f64::consts::PI;

use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::ident::diagnose::augment::Transform;

/// Every effect `generate` can conceal (`none`: a null recording).
pub const EFFECTS: &[&str] = &[
    "none",
    "field_lag",
    "transport_delay",
    "saturation",
    "rate_dependence",
    "asymmetry",
    "thermal_drift",
    "slip_speed",
    "inertia",
    "aux_dependence",
    "sensor_offset",
];
/// Base models of the truth.
pub const BASES: &[&str] = &["algebraic", "bouc_wen", "lugre", "tanh", "dahl"];
/// Field excitations.
pub const EXCITATIONS: &[&str] = &["multisine", "noise", "sweep", "triangle", "bipolar"];

/// Eddy-current time constant between coil current and field, s.
const TAU_EDDY_S: f64 = 0.002;
/// Remanence of the steel, T.
const B_REMANENT_T: f64 = 0.02;
/// Field per ampere, T/A.
const K_T_PER_A: f64 = 0.25;
/// Torque noise, fraction of the torque's span (RMS).
pub const NOISE_OF_SPAN: f64 = 0.005;

/// What to generate.
#[derive(Clone, Debug, PartialEq)]
pub struct ConcealedSpec {
    pub effect: String,
    pub base: String,
    pub excitation: String,
    /// RMS of the effect's change to the torque, fraction of the torque's span.
    pub size: f64,
    pub seed: u64,
    pub duration_s: f64,
    pub fs_hz: f64,
}

impl Default for ConcealedSpec {
    fn default() -> Self {
        Self {
            effect: "none".into(),
            base: "bouc_wen".into(),
            excitation: "multisine".into(),
            size: 0.04,
            seed: 1,
            duration_s: 30.0,
            fs_hz: 2000.0,
        }
    }
}

/// What was concealed: kept out of the recording.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Label {
    pub effect: String,
    pub base: String,
    pub excitation: String,
    pub size: f64,
    pub seed: u64,
    /// True values of the term (names carry their units).
    pub params: BTreeMap<String, f64>,
    /// RMS of the effect's change to the torque, N·m.
    pub effect_rms_nm: f64,
    /// Peak-to-peak torque of the base model, N·m.
    pub torque_span_nm: f64,
    /// RMS of the torque noise added, N·m.
    pub noise_rms_nm: f64,
}

/// A generated recording and its label.
#[derive(Clone, Debug)]
pub struct Concealed {
    /// CSV text, header `t,b,torque,i,speed,temperature`.
    pub csv: String,
    pub label: Label,
}

#[derive(Debug, Error, PartialEq)]
pub enum ConcealedError {
    #[error("unknown effect `{0}` (one of: {list})", list = EFFECTS.join(", "))]
    Effect(String),
    #[error("unknown base model `{0}` (one of: {list})", list = BASES.join(", "))]
    Base(String),
    #[error("unknown excitation `{0}` (one of: {list})", list = EXCITATIONS.join(", "))]
    Excitation(String),
    #[error("--size {0}: must be between 0 and 0.5 (a fraction of the torque span)")]
    Size(f64),
    #[error("--duration {0} s at --fs {1} Hz: need at least 2 s and 200 Hz, at most 10^7 samples")]
    Length(f64, f64),
    #[error("the base model `{0}` diverged on this excitation")]
    Diverged(String),
    #[error(
        "`{effect}` cannot reach size {size} on base `{base}`: at most {reached:.4} of the torque span \
         (e.g. an input offset only shifts the output of a model linear in its input)"
    )]
    Unobservable { effect: String, base: String, size: f64, reached: f64 },
}

/// Clutch-like truth of each base (flux density in T, torque in N·m): each model fitted once
/// to `hil-sim simulate --scenario multisine` (`fit --delay off`), rounded.
pub fn truth(base: &str) -> Option<Vec<(&'static str, f64)>> {
    Some(match base {
        "algebraic" => vec![("t0", 1.02), ("k", 29.3), ("alpha", -31.3), ("c", 0.02)],
        "bouc_wen" => vec![
            ("alpha", 9.03),
            ("beta", 26.0),
            ("gamma", 0.055),
            ("delta", 1.0),
            ("n", 2.0),
            ("c", 0.02),
            ("k", 20.1),
            ("x0", -0.117),
        ],
        "lugre" => {
            vec![("t0", 2.16), ("k", 24.5), ("alpha", 972.0), ("beta", 0.00292), ("epsilon", 0.0296), ("c", 0.02)]
        }
        "tanh" => vec![("t0", 1.93), ("k", 24.4), ("alpha", -0.297), ("beta", 1.21), ("gamma", -1.86), ("c", 0.02)],
        "dahl" => vec![
            ("f0", -2.22),
            ("K0", 25.0),
            ("C0s", 0.000485),
            ("C0d", 0.0),
            ("Fds", 0.000217),
            ("Fdu", 0.0),
            ("sigma", 57000.0),
            ("eta", 190.0),
        ],
        _ => return None,
    })
}

/// The truth's flat parameter vector in the registry's order.
fn flat(base: &str) -> Option<Vec<f32>> {
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

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|a| a * a).sum::<f64>() / v.len().max(1) as f64).sqrt()
}

/// RMS of `a − b` without its mean (a constant offset is absorbed by any base model).
fn diff_rms(a: &[f64], b: &[f64]) -> f64 {
    let d: Vec<f64> = a.iter().zip(b).map(|(a, b)| a - b).collect();
    let m = d.iter().sum::<f64>() / d.len().max(1) as f64;
    rms(&d.iter().map(|v| v - m).collect::<Vec<_>>())
}

/// The base model's torque for the field `b` the model sees (its true rate attached).
fn torque(base: &str, p: &[f32], b: &[f64], dt: f64) -> Result<Vec<f64>, ConcealedError> {
    let rates = crate::rate_offline::rates(b, dt);
    let samples = crate::replay::samples_with_rates(b, None, Some(&rates));
    let r = crate::dispatch::replay(base, p, dt as f32, crate::dispatch::RateChoice::Backward, &samples)
        .map_err(|_| ConcealedError::Diverged(base.to_owned()))?;
    if r.held > 0 {
        return Err(ConcealedError::Diverged(base.to_owned()));
    }
    Ok(r.y.iter().map(|v| f64::from(*v)).collect())
}

/// Bisection for the strength `s` in `[lo, hi]` whose effect has RMS `target` (the RMS grows
/// with `s`).
fn solve(
    mut lo: f64,
    mut hi: f64,
    target: f64,
    log: bool,
    mut rms_at: impl FnMut(f64) -> Result<f64, ConcealedError>,
) -> Result<f64, ConcealedError> {
    for _ in 0..40 {
        let mid = if log { (lo * hi).sqrt() } else { 0.5 * (lo + hi) };
        if rms_at(mid)? < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(if log { (lo * hi).sqrt() } else { 0.5 * (lo + hi) })
}

/// Generate one recording.
pub fn generate(spec: &ConcealedSpec) -> Result<Concealed, ConcealedError> {
    if !EFFECTS.contains(&spec.effect.as_str()) {
        return Err(ConcealedError::Effect(spec.effect.clone()));
    }
    let p = flat(&spec.base).ok_or_else(|| ConcealedError::Base(spec.base.clone()))?;
    if !EXCITATIONS.contains(&spec.excitation.as_str()) {
        return Err(ConcealedError::Excitation(spec.excitation.clone()));
    }
    if !(0.0..=0.5).contains(&spec.size) {
        return Err(ConcealedError::Size(spec.size));
    }
    let n = (spec.duration_s * spec.fs_hz).round();
    if !(spec.duration_s >= 2.0 && spec.fs_hz >= 200.0 && n <= 1e7) {
        return Err(ConcealedError::Length(spec.duration_s, spec.fs_hz));
    }
    let n = n as usize;
    let dt = 1.0 / spec.fs_hz;
    let mut rng = rand::rngs::StdRng::seed_from_u64(spec.seed);
    let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
    let s = excitation(&spec.excitation, &t, spec.duration_s, &mut rng);
    // `bipolar`: the multi-sine through zero (an H-bridge driving the coil both ways), where
    // a zero offset of the Hall reading shows as a kink away from zero.
    let b: Vec<f64> =
        s.iter().map(|s| if spec.excitation == "bipolar" { 0.5 * s } else { 0.325 + 0.275 * s }).collect();
    let (db, _) = crate::rate_offline::rates(&b, dt);
    let db_std = rms(&db.iter().map(|v| v - db.iter().sum::<f64>() / n as f64).collect::<Vec<_>>()).max(1e-12);
    let b_max = b.iter().fold(0.0f64, |a, v| a.max(*v));
    let b_mean = b.iter().sum::<f64>() / n as f64;
    // Auxiliary channels.
    let i: Vec<f64> = b
        .iter()
        .zip(&db)
        .map(|(b, d)| (b + TAU_EDDY_S * d + B_REMANENT_T * (d / (0.1 * db_std)).tanh()) / K_T_PER_A)
        .collect();
    let ph: Vec<f64> = (0..3).map(|_| 2.0 * PI * rng.random::<f64>()).collect();
    let speed: Vec<f64> = t
        .iter()
        .map(|t| {
            20.0 + 4.0 * (2.0 * PI * 0.07 * t + ph[0]).sin()
                + 2.0 * (2.0 * PI * 0.31 * t + ph[1]).sin()
                + 1.5 * (2.0 * PI * 2.3 * t + ph[2]).sin()
        })
        .collect();
    let domega = crate::rate_offline::rates(&speed, dt).0;
    let base = torque(&spec.base, &p, &b, dt)?;
    let (lo, hi) = base.iter().fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
    let span = (hi - lo).max(1e-9);
    // Temperature: heated by the slip power of the base torque.
    let power: Vec<f64> = base.iter().zip(&speed).map(|(t, w)| (t * w).abs()).collect();
    let mean_power = power.iter().sum::<f64>() / n as f64;
    let gain = 10.0 / (mean_power.max(1e-9) * spec.duration_s) * 1.2;
    let mut theta = 25.0;
    let temperature: Vec<f64> = power
        .iter()
        .map(|p| {
            theta += dt * (gain * 60.0 * p - (theta - 25.0)) / 60.0;
            theta
        })
        .collect();

    // The effect.
    let target = spec.size * span;
    let mut params = BTreeMap::new();
    let mut b_recorded_offset = 0.0;
    let with: Vec<f64> = match spec.effect.as_str() {
        "none" => base.clone(),
        "field_lag" | "transport_delay" | "saturation" | "sensor_offset" => {
            let make = |s: f64| match spec.effect.as_str() {
                "field_lag" => Transform::Lag { tau_s: s },
                "transport_delay" => Transform::Delay { delay_s: s },
                "saturation" => Transform::Saturate { b_sat: s },
                // The recorded b reads b + b_0: a model fed the recording sees b + b_0.
                _ => Transform::Offset { b_0: -s },
            };
            let at = |s: f64| torque(&spec.base, &p, &make(s).apply(&b, dt), dt);
            let (name, v) = match spec.effect.as_str() {
                "field_lag" => ("tau_s", solve(1e-5, 0.1, target, true, |s| Ok(diff_rms(&at(s)?, &base)))?),
                "transport_delay" => ("delay_s", solve(0.0, 0.05, target, false, |s| Ok(diff_rms(&at(s)?, &base)))?),
                // A lower saturation level changes more.
                "saturation" => ("b_sat_t", solve(0.02, 50.0, -target, true, |s| Ok(-diff_rms(&at(s)?, &base)))?),
                _ => ("offset_t", solve(0.0, 0.3, target, false, |s| Ok(diff_rms(&at(s)?, &base)))?),
            };
            params.insert(name.to_owned(), v);
            if spec.effect == "sensor_offset" {
                b_recorded_offset = v;
                // The truth is the base on the true field; what the effect changes is what a
                // model fed the recording would get wrong.
                base.clone()
            } else {
                at(v)?
            }
        }
        other => {
            let (name, unit): (&str, Vec<f64>) = match other {
                "rate_dependence" => ("c_rate", db.iter().map(|d| d.abs() * d).collect()),
                "asymmetry" => (
                    "delta_nm_per_t",
                    b.iter().zip(&db).map(|(b, d)| (b - b_mean) * (d / (0.05 * db_std)).tanh()).collect(),
                ),
                "thermal_drift" => {
                    ("kappa_per_k", base.iter().zip(&temperature).map(|(t, th)| -t * (th - 25.0)).collect())
                }
                "slip_speed" => ("c_omega_nms", speed.iter().zip(&b).map(|(w, b)| w * b / b_max).collect()),
                "inertia" => ("j_kgm2", domega.clone()),
                _ => {
                    let i_mean = i.iter().sum::<f64>() / n as f64;
                    let (ilo, ihi) = i.iter().fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
                    ("alpha", base.iter().zip(&i).map(|(t, i)| t * (i - i_mean) / (ihi - ilo).max(1e-9)).collect())
                }
            };
            // Scale on the part that is not a constant offset (the base absorbs that).
            let m = unit.iter().sum::<f64>() / n as f64;
            let k = target / rms(&unit.iter().map(|u| u - m).collect::<Vec<_>>()).max(1e-300);
            params.insert(name.to_owned(), k);
            base.iter().zip(&unit).map(|(t, u)| t + k * u).collect()
        }
    };
    let effect_rms = if spec.effect == "sensor_offset" {
        let seen = Transform::Offset { b_0: -b_recorded_offset }.apply(&b, dt);
        diff_rms(&torque(&spec.base, &p, &seen, dt)?, &base)
    } else {
        diff_rms(&with, &base)
    };

    if spec.effect != "none" && spec.size > 0.0 && (effect_rms / span - spec.size).abs() > 0.1 * spec.size {
        return Err(ConcealedError::Unobservable {
            effect: spec.effect.clone(),
            base: spec.base.clone(),
            size: spec.size,
            reached: effect_rms / span,
        });
    }

    // Measurement chain.
    let lp = |v: &[f64]| Transform::Lag { tau_s: 1.0 / (2.0 * PI * 200.0) }.apply(v, dt);
    let normal = Normal::new(0.0, 1.0).map_err(|_| ConcealedError::Size(spec.size))?;
    let adc = |v: f64, full: f64, bits: i32, noise_counts: f64, rng: &mut rand::rngs::StdRng| {
        let step = 2.0 * full / f64::from(1 << bits);
        ((v + noise_counts * step * normal.sample(rng)) / step).round() * step
    };
    let b_rec: Vec<f64> = lp(&b.iter().map(|v| v + b_recorded_offset).collect::<Vec<_>>())
        .into_iter()
        .map(|v| adc(v, 1.25, 12, 1.0, &mut rng))
        .collect();
    let noise = NOISE_OF_SPAN * span;
    let (tlo, thi) = with.iter().fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
    let t_step = 1.2 * (thi - tlo).max(1e-9) / 65536.0;
    let torque_rec: Vec<f64> =
        lp(&with).into_iter().map(|v| ((v + noise * normal.sample(&mut rng)) / t_step).round() * t_step).collect();
    let i_rec: Vec<f64> = lp(&i).into_iter().map(|v| adc(v, 6.0, 12, 1.0, &mut rng)).collect();
    let speed_rec: Vec<f64> = lp(&speed).into_iter().map(|v| v + 0.01 * normal.sample(&mut rng)).collect();
    let mut csv = String::with_capacity(n * 48);
    csv.push_str("t,b,torque,i,speed,temperature\n");
    for k in 0..n {
        csv.push_str(&format!(
            "{:.6},{:.6},{:.6},{:.5},{:.4},{:.3}\n",
            t[k],
            b_rec[k],
            torque_rec[k],
            i_rec[k],
            speed_rec[k],
            temperature[k] + 0.1 * normal.sample(&mut rng)
        ));
    }
    Ok(Concealed {
        csv,
        label: Label {
            effect: spec.effect.clone(),
            base: spec.base.clone(),
            excitation: spec.excitation.clone(),
            size: spec.size,
            seed: spec.seed,
            params,
            effect_rms_nm: effect_rms,
            torque_span_nm: span,
            noise_rms_nm: noise,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(effect: &str) -> ConcealedSpec {
        ConcealedSpec { effect: effect.into(), duration_s: 4.0, fs_hz: 1000.0, ..Default::default() }
    }

    #[test]
    fn same_seed_same_recording_and_the_label_stays_out() {
        let a = generate(&spec("field_lag")).unwrap();
        let b = generate(&spec("field_lag")).unwrap();
        assert_eq!(a.csv, b.csv);
        assert!(a.csv.starts_with("t,b,torque,i,speed,temperature\n"));
        assert!(!a.csv.contains("lag"));
        let c = generate(&ConcealedSpec { seed: 2, ..spec("field_lag") }).unwrap();
        assert_ne!(a.csv, c.csv);
    }

    #[test]
    fn every_effect_has_the_size_asked_for() {
        for e in EFFECTS.iter().filter(|e| **e != "none") {
            for base in ["bouc_wen", "algebraic"] {
                let g = match generate(&ConcealedSpec { base: base.into(), ..spec(e) }) {
                    Err(ConcealedError::Unobservable { .. }) if *e == "sensor_offset" && base == "bouc_wen" => continue,
                    g => g.unwrap(),
                };
                let share = g.label.effect_rms_nm / g.label.torque_span_nm;
                assert!((share - 0.04).abs() < 0.004, "{e} on {base}: {share}");
                assert_eq!(g.label.params.len(), 1, "{e}");
            }
        }
        let none = generate(&spec("none")).unwrap();
        assert_eq!(none.label.effect_rms_nm, 0.0);
        // Bouc–Wen is linear in its input: an offset only shifts its output, which any fit absorbs.
        let e = generate(&ConcealedSpec { base: "bouc_wen".into(), ..spec("sensor_offset") }).unwrap_err();
        assert!(matches!(e, ConcealedError::Unobservable { .. }), "{e}");
    }

    #[test]
    fn every_base_and_excitation_runs_with_a_span_of_a_few_newton_metres() {
        for base in BASES {
            for exc in EXCITATIONS {
                let g = generate(&ConcealedSpec { base: (*base).into(), excitation: (*exc).into(), ..spec("none") })
                    .unwrap();
                assert!((1.0..40.0).contains(&g.label.torque_span_nm), "{base}/{exc}: {}", g.label.torque_span_nm);
            }
        }
    }

    #[test]
    fn bad_names_list_the_valid_ones() {
        let e = generate(&spec("warp_drive")).unwrap_err();
        assert!(e.to_string().contains("field_lag"), "{e}");
        let e = generate(&ConcealedSpec { base: "x".into(), ..spec("none") }).unwrap_err();
        assert!(e.to_string().contains("bouc_wen"), "{e}");
        assert_eq!(generate(&ConcealedSpec { size: 2.0, ..spec("none") }).unwrap_err(), ConcealedError::Size(2.0));
    }
}
