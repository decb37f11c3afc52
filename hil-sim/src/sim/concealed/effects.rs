//! The concealed effects, from their physics (shared/spec/physics-catalog.md), and their
//! strength: the value (a time constant, a delay, a saturation level, an offset, a
//! coefficient) whose change to the torque has the RMS asked for.
//!
//! The input effects change the field the base model sees:
//!
//! - `field_lag`: `τ·ḃ_f = b − b_f`, discretised exactly for a field held over each step,
//!   `b_f[k] = a·b_f[k−1] + (1 − a)·b[k]`, `a = e^{−Δt/τ}` ([`lag`]);
//! - `transport_delay`: `b(t − d)`, read between samples by linear interpolation and held
//!   at the ends ([`delay`]);
//! - `saturation`: `b_s·tanh(b/b_s)` ([`saturate`]);
//! - `sensor_offset`: the recorded `b` reads `b + b_0`, so a model fed the recording sees
//!   `b + b_0`.
//!
//! The term effects add to (or scale) the torque: `c·|ḃ|·ḃ`, `δ·(b − b̄)·tanh(ḃ/ε)`,
//! `−T·κ·(θ − θ_0)`, `c_ω·ω·b/b_max`, `J·ω̇`, `T·α·(i − ī)/i_span`.

use std::collections::BTreeMap;

use super::spec::{ConcealedError, ConcealedSpec};
use super::truth::{rms, torque, Truth};

/// A first-order lag `τ·ẏ = x − y` of `x` (sample interval `dt`, s), starting at `x[0]`;
/// `τ ≤ 0` passes `x` through.
pub fn lag(x: &[f64], tau_s: f64, dt: f64) -> Vec<f64> {
    let a = if tau_s > 0.0 { (-dt / tau_s).exp() } else { 0.0 };
    let mut y = x.first().copied().unwrap_or(0.0);
    x.iter()
        .map(|v| {
            y = a * y + (1.0 - a) * v;
            y
        })
        .collect()
}

/// `x` delayed by `delay_s` (s, fractional samples allowed; negative: advanced):
/// `y(t) = x(t − delay_s)`, linearly interpolated, the end samples held.
pub fn delay(x: &[f64], delay_s: f64, dt: f64) -> Vec<f64> {
    let d = delay_s / dt;
    if d == 0.0 {
        return x.to_vec();
    }
    let n = x.len();
    let last = n.saturating_sub(1);
    (0..n)
        .map(|k| {
            let pos = (k as f64 - d).clamp(0.0, last as f64);
            let lo = pos.floor();
            let frac = pos - lo;
            let lo = lo as usize;
            let hi = (lo + 1).min(last);
            x[lo] + frac * (x[hi] - x[lo])
        })
        .collect()
}

/// The saturating map `b_s·tanh(x/b_s)`.
pub fn saturate(x: &[f64], b_sat: f64) -> Vec<f64> {
    x.iter().map(|v| b_sat * (v / b_sat).tanh()).collect()
}

/// The field a model fed the recording sees under input effect `effect` of strength `s`.
fn seen(effect: &str, b: &[f64], s: f64, dt: f64) -> Vec<f64> {
    match effect {
        "field_lag" => lag(b, s, dt),
        "transport_delay" => delay(b, s, dt),
        "saturation" => saturate(b, s),
        // The recorded b reads b + b_0.
        _ => b.iter().map(|v| v + s).collect(),
    }
}

/// RMS of `a − b` without its mean (a constant offset is absorbed by any base model).
fn diff_rms(a: &[f64], b: &[f64]) -> f64 {
    let d: Vec<f64> = a.iter().zip(b).map(|(a, b)| a - b).collect();
    let m = d.iter().sum::<f64>() / d.len().max(1) as f64;
    rms(&d.iter().map(|v| v - m).collect::<Vec<_>>())
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

/// The truth with the effect: the torque, the true values (label params), the offset the
/// recorded field reads and the RMS of what the effect changes in the torque (for an
/// offset: in the torque of a model fed the recording).
pub struct Concealment {
    pub torque: Vec<f64>,
    pub params: BTreeMap<String, f64>,
    pub b_offset: f64,
    pub effect_rms: f64,
}

/// Conceal `spec`'s effect in `truth` (base parameters `p`), its strength solved for an
/// RMS change of `spec.size` × the torque's span.
pub fn conceal(spec: &ConcealedSpec, p: &[f32], truth: &Truth) -> Result<Concealment, ConcealedError> {
    let (base, dt) = (&truth.base, truth.dt);
    let target = spec.size * truth.span;
    let effect = spec.effect.as_str();
    let mut params = BTreeMap::new();
    if effect == "none" {
        return Ok(Concealment { torque: base.clone(), params, b_offset: 0.0, effect_rms: 0.0 });
    }
    if let Some((name, unit)) = term(effect, truth) {
        // Scale on the part that is not a constant offset (the base absorbs that).
        let m = unit.iter().sum::<f64>() / unit.len() as f64;
        let k = target / rms(&unit.iter().map(|u| u - m).collect::<Vec<_>>()).max(1e-300);
        params.insert(name.to_owned(), k);
        let with: Vec<f64> = base.iter().zip(&unit).map(|(t, u)| t + k * u).collect();
        let effect_rms = diff_rms(&with, base);
        return Ok(Concealment { torque: with, params, b_offset: 0.0, effect_rms });
    }
    let at = |s: f64| torque(&spec.base, p, &seen(effect, &truth.b, s, dt), dt);
    let rms_at = |s: f64| -> Result<f64, ConcealedError> { Ok(diff_rms(&at(s)?, base)) };
    let (name, v) = match effect {
        "field_lag" => ("tau_s", solve(1e-5, 0.1, target, true, rms_at)?),
        "transport_delay" => ("delay_s", solve(0.0, 0.05, target, false, rms_at)?),
        // A lower saturation level changes more.
        "saturation" => ("b_sat_t", solve(0.02, 50.0, -target, true, |s| Ok(-diff_rms(&at(s)?, base)))?),
        _ => ("offset_t", solve(0.0, 0.3, target, false, rms_at)?),
    };
    params.insert(name.to_owned(), v);
    let with = at(v)?;
    let effect_rms = diff_rms(&with, base);
    if effect == "sensor_offset" {
        // The truth is the base on the true field; what the effect changes is what a model
        // fed the recording would get wrong.
        return Ok(Concealment { torque: base.clone(), params, b_offset: v, effect_rms });
    }
    Ok(Concealment { torque: with, params, b_offset: 0.0, effect_rms })
}

/// A term effect's label name and its shape (the torque change at unit strength); `None`
/// for an input effect.
fn term(effect: &str, truth: &Truth) -> Option<(&'static str, Vec<f64>)> {
    let (b, db, base) = (&truth.b, &truth.db, &truth.base);
    Some(match effect {
        "rate_dependence" => ("c_rate", db.iter().map(|d| d.abs() * d).collect()),
        "asymmetry" => (
            "delta_nm_per_t",
            b.iter().zip(db).map(|(b, d)| (b - truth.b_mean) * (d / (0.05 * truth.db_std)).tanh()).collect(),
        ),
        "thermal_drift" => {
            ("kappa_per_k", base.iter().zip(&truth.temperature).map(|(t, th)| -t * (th - 25.0)).collect())
        }
        "slip_speed" => ("c_omega_nms", truth.speed.iter().zip(b).map(|(w, b)| w * b / truth.b_max).collect()),
        "inertia" => ("j_kgm2", truth.domega.clone()),
        "aux_dependence" => {
            let i = &truth.i;
            let i_mean = i.iter().sum::<f64>() / i.len() as f64;
            let (ilo, ihi) = i.iter().fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
            ("alpha", base.iter().zip(i).map(|(t, i)| t * (i - i_mean) / (ihi - ilo).max(1e-9)).collect())
        }
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_input_effects_do_what_their_physics_says() {
        let dt = 1e-3;
        let x: Vec<f64> = (0..200).map(|i| (i as f64 * 0.05).sin()).collect();
        // A delay of 2.5 samples: halfway between the samples 2 and 3 earlier; the start held.
        let d = delay(&x, 2.5e-3, dt);
        assert!((d[50] - 0.5 * (x[47] + x[48])).abs() < 1e-12);
        assert_eq!(d[0], x[0]);
        assert_eq!(delay(&x, 0.0, dt), x);
        // The lag's step response is 1 − e^{−t/τ} at the samples (exact discretisation).
        let step: Vec<f64> = (0..100).map(|i| if i < 10 { 0.0 } else { 1.0 }).collect();
        let l = lag(&step, 5e-3, dt);
        assert!((l[14] - (1.0 - (-5.0f64 / 5.0).exp())).abs() < 1e-9, "{}", l[14]);
        assert_eq!(lag(&x, 0.0, dt), x);
        let s = saturate(&[2.0, -2.0, 0.0], 0.5);
        assert!(s[0] < 0.5 && s[0] > 0.49 && s[1] == -s[0] && s[2] == 0.0);
    }
}
