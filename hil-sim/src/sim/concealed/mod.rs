//! Recordings with one concealed effect of the missing-physics catalog
//! (shared/spec/physics-catalog.md), for proving `hil-sim diagnose` blind.
//!
//! **Truth** ([`truth`](mod@truth)). The field `b_true(t)` (T, 0.05–0.6 T; ±0.5 T for `bipolar`)
//! follows one of [`EXCITATIONS`]; the torque
//! is one of model-core's models ([`BASES`], a clutch-like parameter set fitted once on
//! `hil-sim simulate --scenario multisine`, see [`truth::truth`]) driven by `b_true` and its true
//! (zero-phase) rate. Every recording carries the same auxiliary channels, effect or not:
//!
//! - `i` (A): the coil current, `i = (b + τ_e·ḃ + b_r·tanh(ḃ/ε))/k` — eddy currents
//!   (τ_e = 2 ms) and the steel's remanence (b_r = 0.02 T) make it more than a copy of `b`;
//! - `speed` (rad/s): the slip speed, 20 rad/s with slow and 2.3 Hz variations, independent
//!   of the field;
//! - `temperature` (°C): a first-order heating state θ̇ = (g·|T·ω| − (θ − 25))/60 s, from 25 °C
//!   up about 10 K over the recording.
//!
//! **The effect** ([`effects`]; one, or `none`), with its strength set so that the RMS of what it changes
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
//! **Measurement chain** ([`chain`], every recording): `b`, `torque`, `i` and `speed` through the lab's
//! first-order 200 Hz anti-alias filter (the same on every channel, so `none` has no delay
//! between channels); `b` on a 12-bit ADC over ±1.25 T with 1 count of noise (as
//! [`crate::sim::plant::sensors`]); `i` on a 12-bit ADC over ±6 A, 1 count; the torque with
//! white noise of 0.5 % of its span, then a 16-bit quantiser over its range; the temperature
//! with 0.1 K of noise. The label (which effect, its true values) stays out of the
//! recording (the CLI writes it to a separate file).

pub mod chain;
pub mod effects;
pub mod spec;
pub mod truth;

use std::collections::BTreeMap;

use crate::io::recording::Recording;
use rand::SeedableRng;
use serde::{Deserialize, Serialize};

pub use chain::NOISE_OF_SPAN;
pub use spec::{ConcealedError, ConcealedSpec, BASES, EFFECTS, EXCITATIONS, MAX_SIZE};

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
    /// Channels `t,b,torque,i,speed,temperature`, as the logger wrote them.
    pub recording: Recording,
    pub label: Label,
}

/// The truth's parameters of a valid `spec`, and its number of samples.
fn check(spec: &ConcealedSpec) -> Result<(Vec<f32>, usize), ConcealedError> {
    if !EFFECTS.contains(&spec.effect.as_str()) {
        return Err(ConcealedError::Effect(spec.effect.clone()));
    }
    let p = truth::flat(&spec.base).ok_or_else(|| ConcealedError::Base(spec.base.clone()))?;
    if !EXCITATIONS.contains(&spec.excitation.as_str()) {
        return Err(ConcealedError::Excitation(spec.excitation.clone()));
    }
    if !(0.0..=MAX_SIZE).contains(&spec.size) {
        return Err(ConcealedError::Size(spec.size));
    }
    let n = (spec.duration_s * spec.fs_hz).round();
    if !(spec.duration_s >= 2.0 && spec.fs_hz >= 200.0 && n <= 1e7) {
        return Err(ConcealedError::Length(spec.duration_s, spec.fs_hz));
    }
    Ok((p, n as usize))
}

/// Generate one recording.
pub fn generate(spec: &ConcealedSpec) -> Result<Concealed, ConcealedError> {
    let (p, n) = check(spec)?;
    let dt = 1.0 / spec.fs_hz;
    let mut rng = rand::rngs::StdRng::seed_from_u64(spec.seed);
    let truth = truth::Truth::new(spec, &p, n, dt, &mut rng)?;
    let effect = effects::conceal(spec, &p, &truth)?;
    let span = truth.span;
    if spec.effect != "none" && spec.size > 0.0 && (effect.effect_rms / span - spec.size).abs() > 0.1 * spec.size {
        return Err(ConcealedError::Unobservable {
            effect: spec.effect.clone(),
            base: spec.base.clone(),
            size: spec.size,
            reached: effect.effect_rms / span,
        });
    }
    let (recording, noise) = chain::record(&truth, &effect, &mut rng);
    Ok(Concealed {
        recording,
        label: Label {
            effect: spec.effect.clone(),
            base: spec.base.clone(),
            excitation: spec.excitation.clone(),
            size: spec.size,
            seed: spec.seed,
            params: effect.params,
            effect_rms_nm: effect.effect_rms,
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

    /// The recording as the CLI writes it.
    fn csv(g: &Concealed) -> String {
        let mut out = Vec::new();
        g.recording.write_csv(&mut out).unwrap();
        String::from_utf8(out).unwrap()
    }

    #[test]
    fn same_seed_same_recording_and_the_label_stays_out() {
        let (a, b) = (generate(&spec("field_lag")).unwrap(), generate(&spec("field_lag")).unwrap());
        let (a, b) = (csv(&a), csv(&b));
        assert_eq!(a, b);
        assert!(a.starts_with("t,b,torque,i,speed,temperature\n"));
        assert!(!a.contains("lag"));
        let c = csv(&generate(&ConcealedSpec { seed: 2, ..spec("field_lag") }).unwrap());
        assert_ne!(a, c);
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
