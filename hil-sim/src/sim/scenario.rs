//! Scenarios: what drives the simulated clutch, for how long, and which clutch.
//!
//! Built-in names ([`Scenario::builtin`], listed by [`BUILTIN`]) or a TOML file that
//! describes a user's own clutch and excitation, e.g.
//!
//! ```toml
//! name = "my_clutch_3hz"
//! duration_s = 10.0
//! [reference]
//! quantity = "current"      # or "torque"
//! lo = 0.0
//! hi = 3.0
//! signal = { kind = "sine", f = 3.0 }
//! [clutch.coil]
//! r20 = 6.5
//! l = 0.035
//! [clutch.motor]
//! speed = [[0.0, 20.0], [5.0, 40.0]]
//! ```
//!
//! Every `[clutch.*]` field not given keeps the reference clutch's value
//! ([`ClutchParams::default`]).

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use rand::{Rng, SeedableRng};
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::sim::excitation::Excitation;
use crate::sim::plant::ClutchParams;

/// A unit test signal (range −1…1).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Signal {
    /// `sin(2π f t)`.
    Sine { f: f64 },
    /// Seed 000 eq. 21 (11 sines, 1–10 Hz).
    Multisine,
    /// Seed 000 eq. 22 from `f0` to `f1` Hz over the scenario's duration.
    Swept { f0: f64, f1: f64 },
    /// Seed 004's triangle.
    Triangle { f: f64 },
    /// Band-limited noise: 64 random-phase sines spread over 0.1…`fc` Hz (fixed `seed`),
    /// RMS 0.35, clipped to ±1.
    Noise { fc: f64, seed: u64 },
    /// Levels (unit range) held `dwell` s each, repeated.
    Steps { levels: Vec<f64>, dwell: f64 },
    /// A constant.
    Constant { value: f64 },
}

/// What the reference is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Quantity {
    /// Coil current, A (a current driver, as in seed 000's experiments).
    Current,
    /// Torque, N·m (the closed loop).
    Torque,
}

/// Reference `lo + (hi − lo)·(u + 1)/2` for the unit signal `u`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Reference {
    pub quantity: Quantity,
    pub lo: f64,
    pub hi: f64,
    pub signal: Signal,
}

/// One scenario.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Scenario {
    pub name: String,
    pub description: String,
    pub duration_s: f64,
    /// Control-step rate, Hz (the firmware's ADC interrupt).
    pub control_hz: f64,
    /// Rate of the written recording, Hz.
    pub record_hz: f64,
    /// Noise seed.
    pub seed: u64,
    pub reference: Reference,
    pub clutch: ClutchParams,
}

impl Default for Scenario {
    fn default() -> Self {
        Self {
            name: "custom".into(),
            description: String::new(),
            duration_s: 10.0,
            control_hz: 10_000.0,
            record_hz: 1000.0,
            seed: 1,
            reference: Reference { quantity: Quantity::Current, lo: 0.0, hi: 3.0, signal: Signal::Sine { f: 1.0 } },
            clutch: ClutchParams::default(),
        }
    }
}

/// Why a scenario could not be loaded.
#[derive(Debug, Error)]
pub enum ScenarioError {
    #[error("unknown scenario `{name}` (built-in: {list}; or a .toml file)")]
    Unknown { name: String, list: String },
    #[error("{path}: cannot read: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("{path}: line {line}, column {column}: {message}")]
    Toml { path: PathBuf, line: usize, column: usize, message: String },
    #[error("{path}: {what}")]
    Invalid { path: PathBuf, what: String },
}

/// Built-in recording scenarios of `hil-sim simulate`.
pub const BUILTIN: &[&str] = &[
    "sine_1hz",
    "sine_3hz",
    "sine_5hz",
    "sine_7hz",
    "sine_9hz",
    "multisine",
    "sweep",
    "triangle",
    "triangle_asym",
    "noise",
    "cold_start",
    "heating",
    "speed_change",
];

impl Signal {
    /// Value at `t` s of a signal lasting `duration` s.
    pub fn at(&self, t: f64, duration: f64) -> f64 {
        match self {
            Self::Sine { f } => Excitation::Sine { f: *f }.at(t).x,
            Self::Multisine => Excitation::seed000_multisine().at(t).x,
            Self::Swept { f0, f1 } => Excitation::SweptSine { f0: *f0, f1: *f1, duration }.at(t).x,
            Self::Triangle { f } => Excitation::Triangle { f: *f }.at(t).x,
            Self::Noise { fc, seed } => {
                let mut rng = rand::rngs::StdRng::seed_from_u64(*seed);
                let n = 64;
                let amp = 0.35 * (2.0 / n as f64).sqrt();
                let mut x = 0.0;
                for k in 0..n {
                    let f = 0.1 + (fc - 0.1) * (k as f64 + rng.random::<f64>()) / n as f64;
                    let ph = 2.0 * PI * rng.random::<f64>();
                    x += amp * (2.0 * PI * f * t + ph).sin();
                }
                x.clamp(-1.0, 1.0)
            }
            Self::Steps { levels, dwell } => {
                if levels.is_empty() || *dwell <= 0.0 {
                    return 0.0;
                }
                let k = (t / dwell).floor().max(0.0) as usize % levels.len();
                levels.get(k).copied().unwrap_or(0.0)
            }
            Self::Constant { value } => *value,
        }
    }
}

impl Reference {
    /// Reference at `t` s, in A or N·m.
    pub fn at(&self, t: f64, duration: f64) -> f64 {
        self.lo + (self.hi - self.lo) * (self.signal.at(t, duration) + 1.0) / 2.0
    }
}

fn current(signal: Signal) -> Reference {
    Reference { quantity: Quantity::Current, lo: 0.0, hi: 3.0, signal }
}

impl Scenario {
    /// A built-in scenario by name.
    pub fn builtin(name: &str) -> Option<Self> {
        let base = Self { name: name.into(), ..Self::default() };
        let sine = |f: f64| Self {
            description: format!("seed 000 fitting sine, {f} Hz, 0-3 A"),
            duration_s: 10.0,
            reference: current(Signal::Sine { f }),
            ..base.clone()
        };
        Some(match name {
            "sine_1hz" => sine(1.0),
            "sine_3hz" => sine(3.0),
            "sine_5hz" => sine(5.0),
            "sine_7hz" => sine(7.0),
            "sine_9hz" => sine(9.0),
            "multisine" => Self {
                description: "seed 000 eq. 21 multi-sine, 1-10 Hz, 0-3 A, 40 s".into(),
                duration_s: 40.0,
                reference: current(Signal::Multisine),
                ..base
            },
            "sweep" => Self {
                description: "seed 000 eq. 22 swept sine 0.1-5 Hz, 0-3 A, 40 s".into(),
                duration_s: 40.0,
                reference: current(Signal::Swept { f0: 0.1, f1: 5.0 }),
                ..base
            },
            "triangle" => Self {
                description: "seed 004 triangle, 0.1 Hz, 0-3 A, 30 s".into(),
                duration_s: 30.0,
                reference: current(Signal::Triangle { f: 0.1 }),
                ..base
            },
            "triangle_asym" => {
                // Seed 004's loop shape (Fig. 3): wide at the bottom, pointed at the top. A
                // soft, wide magnetic hysteresis (coercive current ≈ 0.35 A) feeds a yoke and
                // a fluid that saturate early, so the loop closes towards full current; at a
                // slow, constant slip without warming, the loop is all there is.
                let mut c = ClutchParams::default();
                c.magnetic.r_max = 1.2;
                c.magnetic.r_w = 0.6;
                c.magnetic.n_play = 16;
                c.magnetic.i_sat = 1.6;
                c.fluid.b_tau = 0.35;
                c.fluid.thermal_effects = false;
                c.motor.speed = vec![[0.0, 5.0]];
                c.motor.ripple = 0.0;
                Self {
                    description: "seed 004-like asymmetric loop: triangle 0.1 Hz, 0-3 A, saturating clutch, 30 s"
                        .into(),
                    duration_s: 30.0,
                    reference: current(Signal::Triangle { f: 0.1 }),
                    clutch: c,
                    ..base
                }
            }
            "noise" => Self {
                description: "band-limited noise 0.1-10 Hz, 0-3 A, 40 s".into(),
                duration_s: 40.0,
                reference: current(Signal::Noise { fc: 10.0, seed: 7 }),
                ..base
            },
            "cold_start" => {
                let mut c = ClutchParams { ambient_c: 0.0, initial_c: 0.0, ..ClutchParams::default() };
                c.motor.speed = vec![[0.0, 60.0]];
                Self {
                    description:
                        "cold start at 0 °C, multi-sine 0-3 A at 60 rad/s slip, 60 s (viscous drag falls as it warms)"
                            .into(),
                    duration_s: 60.0,
                    reference: current(Signal::Multisine),
                    clutch: c,
                    ..base
                }
            }
            "heating" => {
                let mut c = ClutchParams::default();
                c.motor.speed = vec![[0.0, 60.0]];
                Self {
                    description: "heating: 1 Hz sine 1.5-3 A at 60 rad/s slip for 90 s (≈ 400 W slip power)".into(),
                    duration_s: 90.0,
                    reference: Reference {
                        quantity: Quantity::Current,
                        lo: 1.5,
                        hi: 3.0,
                        signal: Signal::Sine { f: 1.0 },
                    },
                    clutch: c,
                    ..base
                }
            }
            "speed_change" => {
                let mut c = ClutchParams::default();
                c.motor.speed = vec![[0.0, 20.0], [4.0, 20.0], [4.5, 60.0], [10.0, 60.0], [10.5, 10.0]];
                Self {
                    description: "3 Hz sine 0-3 A while the input speed steps 20 → 60 → 10 rad/s".into(),
                    duration_s: 15.0,
                    reference: current(Signal::Sine { f: 3.0 }),
                    clutch: c,
                    ..base
                }
            }
            _ => return None,
        })
    }

    /// A built-in name, or a path to a TOML file.
    pub fn load(name: &str) -> Result<Self, ScenarioError> {
        if let Some(s) = Self::builtin(name) {
            return Ok(s);
        }
        let path = Path::new(name);
        if path.extension().is_some_and(|e| e == "toml") || path.is_file() {
            let text = std::fs::read_to_string(path)
                .map_err(|source| ScenarioError::Io { path: path.to_path_buf(), source })?;
            return Self::parse(path, &text);
        }
        Err(ScenarioError::Unknown { name: name.into(), list: BUILTIN.join(", ") })
    }

    /// Parse TOML text; `path` names it in messages.
    pub fn parse(path: &Path, text: &str) -> Result<Self, ScenarioError> {
        let s: Self = toml::from_str(text).map_err(|e: toml::de::Error| {
            let at = e.span().map_or(0, |r| r.start).min(text.len());
            let before = text.get(..at).unwrap_or("");
            ScenarioError::Toml {
                path: path.to_path_buf(),
                line: before.matches('\n').count() + 1,
                column: before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1,
                message: e.message().split_whitespace().collect::<Vec<_>>().join(" "),
            }
        })?;
        let bad = |what: &str| Err(ScenarioError::Invalid { path: path.to_path_buf(), what: what.into() });
        if !(s.duration_s > 0.0 && s.duration_s.is_finite()) {
            return bad("duration_s must be > 0");
        }
        if !(1000.0..=100_000.0).contains(&s.control_hz) {
            return bad("control_hz must be within 1 kHz … 100 kHz");
        }
        if !(s.record_hz > 0.0 && s.record_hz <= s.control_hz) {
            return bad("record_hz must be in (0, control_hz]");
        }
        let c = &s.clutch;
        if !(c.coil.r20 > 0.0 && c.coil.l > 0.0 && c.coil.pwm_hz > 0.0 && c.pwm_substeps > 0) {
            return bad("clutch.coil: r20, l, pwm_hz and pwm_substeps must be > 0");
        }
        if !(c.magnetic.i_sat > 0.0 && c.magnetic.r_w > 0.0 && c.fluid.b_tau > 0.0 && c.fluid.gap > 0.0) {
            return bad("clutch: i_sat, r_w, b_tau and gap must be > 0");
        }
        if !(c.thermal.capacity > 0.0 && c.thermal.r_th > 0.0) {
            return bad("clutch.thermal: capacity and r_th must be > 0");
        }
        if let Some(field) = non_finite(&s) {
            return bad(&format!("{field}: not a finite number"));
        }
        if let Err(e) = c.check_run(s.duration_s, s.control_hz).and_then(|()| c.check_physical()) {
            return bad(&e.to_string());
        }
        if s.duration_s * s.record_hz < 2.0 {
            return bad(&format!(
                "duration_s = {}: gives {:.3} rows at record_hz = {} Hz, need at least 2",
                crate::numerics::shown(s.duration_s),
                s.duration_s * s.record_hz,
                s.record_hz
            ));
        }
        Ok(s)
    }
}

/// The dotted name of the first number of `s` that is NaN or infinite.
fn non_finite(s: &Scenario) -> Option<String> {
    fn walk(prefix: &str, v: &toml::Value) -> Option<String> {
        match v {
            toml::Value::Float(f) if !f.is_finite() => Some(prefix.to_owned()),
            toml::Value::Table(t) => t
                .iter()
                .find_map(|(k, v)| walk(&if prefix.is_empty() { k.clone() } else { format!("{prefix}.{k}") }, v)),
            toml::Value::Array(a) => a.iter().enumerate().find_map(|(i, v)| walk(&format!("{prefix}[{i}]"), v)),
            _ => None,
        }
    }
    walk("", &toml::Value::try_from(s).ok()?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtins_load_and_stay_in_range() {
        for name in BUILTIN {
            let s = Scenario::load(name).unwrap();
            assert_eq!(s.clutch.check_run(s.duration_s, s.control_hz), Ok(()), "{name}");
            assert_eq!(s.clutch.check_physical(), Ok(()), "{name}");
            assert!(non_finite(&s).is_none(), "{name}");
            for k in 0..2000 {
                let t = k as f64 * s.duration_s / 2000.0;
                let r = s.reference.at(t, s.duration_s);
                assert!(r >= s.reference.lo - 1e-9 && r <= s.reference.hi + 1e-9, "{name} at {t}: {r}");
            }
        }
        assert!(matches!(Scenario::load("nope"), Err(ScenarioError::Unknown { .. })));
    }

    #[test]
    fn toml_describes_a_users_clutch() {
        let text = r#"
            name = "mine"
            duration_s = 2.0
            [reference]
            quantity = "torque"
            lo = 1.0
            hi = 5.0
            signal = { kind = "steps", levels = [-1.0, 1.0], dwell = 0.5 }
            [clutch.coil]
            r20 = 6.5
            [clutch.motor]
            speed = [[0.0, 20.0], [1.0, 40.0]]
        "#;
        let s = Scenario::parse(Path::new("mine.toml"), text).unwrap();
        assert_eq!(s.clutch.coil.r20, 6.5);
        assert_eq!(s.clutch.coil.l, 0.02, "unspecified fields keep the reference clutch");
        assert_eq!(s.reference.at(0.7, 2.0), 5.0);
        let e = Scenario::parse(Path::new("bad.toml"), "duration_s = 1.0\n[clutch.coil]\nohms = 3\n").unwrap_err();
        assert!(e.to_string().contains("bad.toml") && e.to_string().contains("ohms"), "{e}");
        let e = Scenario::parse(Path::new("bad.toml"), "duration_s = -1.0\n").unwrap_err();
        assert!(e.to_string().contains("duration_s"), "{e}");
    }
}
