//! The bench's concealed effects, each written from its physics in two or three forms, its
//! strength solved (bisection) so that the RMS of what it changes in the torque (about its
//! mean) is the size asked for.
//!
//! | effect | forms |
//! | --- | --- |
//! | `field_lag` | first-order lag `τ·ḃ_f = b − b_f`; two poles `τ/2` each; an eddy share `0.3·b + 0.7·b_f` |
//! | `transport_delay` | the torque responds `d` late (`b(t − d)`); the Hall channel is logged `d` late (fractional, cubic interpolation) |
//! | `saturation` | of the field `b_s·tanh(b/b_s)`; of the field, sharper knee `b/(1 + (b/b_s)⁴)^¼`; of the yield stress `T_lo + u/√(1 + (u/S)²)` |
//! | `rate_dependence` | `c·|ḃ|·ḃ`; a damping coefficient growing with the local excitation frequency `c·f_loc(t)·ḃ`; `c·ḃ³` (sized by the part beyond a linear damping `c·ḃ`) |
//! | `asymmetry` | `δ·(b − b̄)·tanh(ḃ/ε)`; loading branch only `δ·(b − b_min)·(1 + tanh(ḃ/ε))/2`; quadratic `δ·(b − b̄)²·tanh(ḃ/ε)` |
//! | `thermal_drift` | the heating state `θ` (driven by the slip power `|T·ω|`) scales the torque `T·(1 − κ·θ)`; shifts it `−κ·θ` (off-state drift); lowers the yield part `−κ·θ·(T − T_lo)` |
//! | `slip_speed` | `c_ω·ω`; `c_ω·ω·b/b_max`; `c_ω·√ω` |
//! | `inertia` | `J·ω̇`; `J·ω̇` through a 5 ms shaft lag |
//!
//! `aux_dependence` is not concealed: the only auxiliary channel a clutch recording carries
//! besides speed and temperature is the coil current, and what it holds beyond the Hall
//! reading is the field's own dynamics (eddy lag, remanence), a function of the field and
//! its rate: a torque scaled by it is a `field_lag`, `saturation` or `asymmetry` by
//! another name, and the diagnosis (rightly) does not use such a channel as a cause.
//! `sensor_offset` is not concealed: a Hall offset a clutch can have (tens of mT) changes
//! the torque of these bases by less than 3 % of the span once their own offset is
//! refitted, and an offset that reaches 3 % is a third of the field's range.

use std::collections::BTreeMap;

use super::plant;
use super::signals::{delayed, derivative, first_order, rms_about_mean};
use super::World;

/// Every effect the bench conceals (`none`: a null recording) and its number of forms.
pub const EFFECTS: &[(&str, usize)] = &[
    ("field_lag", 3),
    ("transport_delay", 2),
    ("saturation", 3),
    ("rate_dependence", 3),
    ("asymmetry", 3),
    ("thermal_drift", 3),
    ("slip_speed", 3),
    ("inertia", 2),
];

/// The truth with the effect.
pub struct Applied {
    /// The true torque, N·m.
    pub torque: Vec<f64>,
    /// The field the Hall probe reports before its ADC, T.
    pub b_reported: Vec<f64>,
    /// The form's name and its true values (names carry units).
    pub form: String,
    pub params: BTreeMap<String, f64>,
    /// RMS of what the effect changes in the torque a model fed the recording must explain.
    pub effect_rms: f64,
}

/// Bisection for the strength in `[lo, hi]` whose RMS is `target`; `rising`: the RMS grows
/// with the strength. Log-spaced when `lo > 0`.
fn solve(mut lo: f64, mut hi: f64, target: f64, rising: bool, rms_at: impl Fn(f64) -> f64) -> f64 {
    let log = lo > 0.0;
    for _ in 0..36 {
        let mid = if log { (lo * hi).sqrt() } else { 0.5 * (lo + hi) };
        if (rms_at(mid) < target) == rising {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    if log {
        (lo * hi).sqrt()
    } else {
        0.5 * (lo + hi)
    }
}

fn diff_rms(a: &[f64], b: &[f64]) -> f64 {
    rms_about_mean(&a.iter().zip(b).map(|(a, b)| a - b).collect::<Vec<_>>())
}

/// The base torque for the field `seen` (its own rate).
fn plant_on(w: &World, seen: &[f64]) -> Vec<f64> {
    let d = derivative(seen, w.dt);
    plant::torque(&w.family, seen, &d, w.dt).unwrap_or_else(|| vec![f64::NAN; seen.len()])
}

/// A term added to the torque, scaled to RMS `target`.
fn additive(w: &World, shape: Vec<f64>, target: f64, name: &str) -> (Vec<f64>, BTreeMap<String, f64>) {
    let k = target / rms_about_mean(&shape).max(1e-300);
    let torque = w.base.iter().zip(&shape).map(|(t, s)| t + k * s).collect();
    (torque, BTreeMap::from([(name.to_owned(), k)]))
}

/// Conceal `effect` in form `form` (taken modulo its number of forms) at size `size` × span.
pub fn apply(w: &World, effect: &str, form: usize, size: f64) -> Applied {
    let target = size * w.span;
    let n_forms = EFFECTS.iter().find(|(e, _)| *e == effect).map_or(1, |(_, n)| *n);
    let form = form % n_forms;
    let dt = w.dt;
    let unchanged = |torque: Vec<f64>, form: &str, params: BTreeMap<String, f64>| {
        let effect_rms = diff_rms(&torque, &w.base);
        Applied { torque, b_reported: w.b.clone(), form: form.to_owned(), params, effect_rms }
    };
    match effect {
        "field_lag" | "saturation" if !(effect == "saturation" && form == 2) => {
            let seen_at = |s: f64| -> Vec<f64> {
                match (effect, form) {
                    ("field_lag", 0) => first_order(&w.b, s, dt),
                    ("field_lag", 1) => first_order(&first_order(&w.b, 0.5 * s, dt), 0.5 * s, dt),
                    ("field_lag", _) => {
                        w.b.iter().zip(first_order(&w.b, s, dt)).map(|(b, f)| 0.3 * b + 0.7 * f).collect()
                    }
                    ("saturation", 0) => w.b.iter().map(|b| s * (b / s).tanh()).collect(),
                    _ => w.b.iter().map(|b| b / (1.0 + (b / s).powi(4)).powf(0.25)).collect(),
                }
            };
            let rms_at = |s: f64| diff_rms(&plant_on(w, &seen_at(s)), &w.base);
            let (s, name, label) = match (effect, form) {
                ("field_lag", f) => {
                    (solve(1e-4, 0.2, target, true, rms_at), "tau_s", ["first-order", "two-pole", "eddy share"][f])
                }
                (_, f) => (solve(0.05, 50.0, target, false, rms_at), "b_sat_t", ["tanh", "sharp knee"][f]),
            };
            unchanged(plant_on(w, &seen_at(s)), label, BTreeMap::from([(name.to_owned(), s)]))
        }
        "saturation" => {
            let t_lo = w.base.iter().fold(f64::MAX, |a, v| a.min(*v));
            let at = |s: f64| -> Vec<f64> {
                w.base.iter().map(|t| t_lo + (t - t_lo) / (1.0 + ((t - t_lo) / s).powi(2)).sqrt()).collect()
            };
            let s = solve(0.05 * w.span, 100.0 * w.span, target, false, |s| diff_rms(&at(s), &w.base));
            unchanged(at(s), "yield stress", BTreeMap::from([("t_sat_nm".to_owned(), s)]))
        }
        "transport_delay" => {
            let rms_at = |d: f64| diff_rms(&plant_on(w, &delayed(&w.b, d, dt)), &w.base);
            let d = solve(0.0, 0.03, target, true, rms_at);
            let params = BTreeMap::from([("delay_s".to_owned(), d)]);
            if form == 0 {
                unchanged(plant_on(w, &delayed(&w.b, d, dt)), "torque late", params)
            } else {
                let b_reported = delayed(&w.b, d, dt);
                let effect_rms = diff_rms(&plant_on(w, &b_reported), &w.base);
                Applied { torque: w.base.clone(), b_reported, form: "Hall channel late".into(), params, effect_rms }
            }
        }
        "rate_dependence" => {
            // The catalog's rate dependence is what goes beyond the linear `c·ḃ` every base
            // has: the term is added whole, its strength set by the part a refitted linear
            // damping cannot take (the least-squares share along `ḃ` taken out).
            let (shape, name, label) = term_shape(w, effect, form);
            let beyond = beyond_linear_damping(&shape, &w.db);
            let k = target / rms_about_mean(&beyond).max(1e-300);
            let torque = w.base.iter().zip(&shape).map(|(t, s)| t + k * s).collect();
            Applied {
                torque,
                b_reported: w.b.clone(),
                form: label.into(),
                params: BTreeMap::from([(name.to_owned(), k)]),
                effect_rms: k * rms_about_mean(&beyond),
            }
        }
        _ => {
            let (shape, name, label) = term_shape(w, effect, form);
            let (torque, params) = additive(w, shape, target, name);
            unchanged(torque, label, params)
        }
    }
}

/// `shape` less its least-squares share along the rate `db` (both about their means).
fn beyond_linear_damping(shape: &[f64], db: &[f64]) -> Vec<f64> {
    let n = shape.len().max(1) as f64;
    let (ms, md) = (shape.iter().sum::<f64>() / n, db.iter().sum::<f64>() / n);
    let (sd, dd) =
        shape.iter().zip(db).fold((0.0, 0.0), |(sd, dd), (s, d)| (sd + (s - ms) * (d - md), dd + (d - md) * (d - md)));
    let beta = if dd > 0.0 { sd / dd } else { 0.0 };
    shape.iter().zip(db).map(|(s, d)| (s - ms) - beta * (d - md)).collect()
}

/// The shape (torque change at unit strength) of a term effect's form.
fn term_shape(w: &World, effect: &str, form: usize) -> (Vec<f64>, &'static str, &'static str) {
    let (b, db, dt) = (&w.b, &w.db, w.dt);
    let eps = 0.1 * rms_about_mean(db).max(1e-9);
    let b_mean = b.iter().sum::<f64>() / b.len() as f64;
    let b_min = b.iter().fold(f64::MAX, |a, v| a.min(*v));
    let b_max = b.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(1e-9);
    let t_lo = w.base.iter().fold(f64::MAX, |a, v| a.min(*v));
    let theta: Vec<f64> = w.temperature.iter().map(|t| t - super::AMBIENT_C).collect();
    match (effect, form) {
        ("rate_dependence", 0) => (db.iter().map(|d| d.abs() * d).collect(), "c_nm_s2_per_t2", "|rate|·rate"),
        ("rate_dependence", 1) => {
            // The local excitation frequency: RMS rate over 2π·RMS level about the local
            // mean, both over the last second (a first-order average, τ = 0.5 s).
            let level = first_order(b, 0.5, dt);
            let dev2: Vec<f64> = b.iter().zip(&level).map(|(b, m)| (b - m).powi(2)).collect();
            let rate2: Vec<f64> = db.iter().map(|d| d * d).collect();
            let (dev2, rate2) = (first_order(&dev2, 0.5, dt), first_order(&rate2, 0.5, dt));
            let f: Vec<f64> = dev2
                .iter()
                .zip(&rate2)
                .map(|(v, r)| (r.sqrt() / (2.0 * std::f64::consts::PI * v.sqrt().max(1e-6))).min(30.0))
                .collect();
            (db.iter().zip(&f).map(|(d, f)| d * f).collect(), "c_nm_s2_per_t", "damping growing with the frequency")
        }
        ("rate_dependence", _) => (db.iter().map(|d| d * d * d).collect(), "c_nm_s3_per_t3", "rate cubed"),
        ("asymmetry", 0) => (
            b.iter().zip(db).map(|(b, d)| (b - b_mean) * (d / eps).tanh()).collect(),
            "delta_nm_per_t",
            "direction × level",
        ),
        ("asymmetry", 1) => (
            b.iter().zip(db).map(|(b, d)| (b - b_min) * 0.5 * (1.0 + (d / eps).tanh())).collect(),
            "delta_nm_per_t",
            "loading branch only",
        ),
        ("asymmetry", _) => (
            b.iter().zip(db).map(|(b, d)| (b - b_mean).powi(2) * (d / eps).tanh()).collect(),
            "delta_nm_per_t2",
            "direction × level²",
        ),
        ("thermal_drift", 0) => {
            (w.base.iter().zip(&theta).map(|(t, th)| -t * th).collect(), "kappa_per_k", "torque scaled")
        }
        ("thermal_drift", 1) => (theta.iter().map(|th| -th).collect(), "kappa_nm_per_k", "off-state drift"),
        ("thermal_drift", _) => {
            (w.base.iter().zip(&theta).map(|(t, th)| -(t - t_lo) * th).collect(), "kappa_per_k", "yield part falls")
        }
        ("slip_speed", 0) => (w.speed.clone(), "c_omega_nm_s", "viscous"),
        ("slip_speed", 1) => {
            (w.speed.iter().zip(b).map(|(s, b)| s * b / b_max).collect(), "c_omega_nm_s", "viscous × field")
        }
        ("slip_speed", _) => (w.speed.iter().map(|s| s.abs().sqrt()).collect(), "c_nm_per_sqrt_rad_s", "√speed"),
        ("inertia", 0) => (w.domega.clone(), "j_kgm2", "rotor"),
        ("inertia", _) => (first_order(&w.domega, 0.005, dt), "j_kgm2", "rotor through a shaft lag"),
        _ => (vec![0.0; b.len()], "none", "none"),
    }
}
