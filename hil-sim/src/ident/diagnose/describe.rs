//! Stage 5 of a diagnosis, the finding: which physics (in words, with the recording's
//! channel names and units), how big (the fitted values and the RMS of what the term adds,
//! output units and share of the output's span), where (the windows and operating
//! conditions where the drop in squared error concentrates, [`super::locate`]) and the
//! held-out error before and after.

use std::collections::BTreeMap;

use super::augment::Fitted;
use super::candidates::Candidate;
use super::diagnosis::{Evidence, Finding};
use super::locate::{self, Condition};
use super::significance::Test;
use crate::ident::fit::Dataset;
use crate::numerics::metrics::Metrics;

/// Everything a finding is described from.
pub struct Described<'a> {
    pub data: &'a Dataset,
    pub candidate: &'a Candidate,
    /// The model with the candidate's term, and the round's reference without it.
    pub fitted: &'a Fitted,
    pub reference: &'a Fitted,
    /// The candidate's value (0 without a grid).
    pub value: f64,
    /// Names of the input and output channels.
    pub names: (&'a str, &'a str),
    /// Held-out metrics of the reference and of the fitted model.
    pub before: Metrics,
    pub after: Metrics,
    pub test: Test,
    pub bic_gain: f64,
    /// Span (peak to peak) of the output on the held-out rows.
    pub y_span: f64,
    /// The input's rate and the auxiliary channels (name, values), for the conditions.
    pub rate: &'a [f64],
    pub aux: &'a [(&'a str, &'a [f64])],
    /// Rows the term's size and the conditions are taken over.
    pub rows: &'a [usize],
}

pub use crate::numerics::units::unit_of;

/// A finding's text, values, windows and conditions.
pub fn finding(d: &Described<'_>) -> Finding {
    let (data, c, f, reference, g) = (d.data, d.candidate, d.fitted, d.reference, d.value);
    let y = &data.output;
    let (xu, yu) = (unit_of(d.names.0).unwrap_or(""), unit_of(d.names.1).unwrap_or(""));
    let change: Vec<f64> = f.pred.iter().zip(&reference.pred).map(|(a, b)| a - b).collect();
    let term_rms = (d.rows.iter().map(|&i| change[i] * change[i]).sum::<f64>() / d.rows.len().max(1) as f64).sqrt();
    let share = term_rms / d.y_span;
    let mut gain_e: Vec<f64> =
        (0..y.len()).map(|i| (y[i] - reference.pred[i]).powi(2) - (y[i] - f.pred[i]).powi(2)).collect();
    locate::mask(&mut gain_e, d.rows);
    let gain_pos: Vec<f64> = gain_e.iter().map(|v| v.max(0.0)).collect();
    let windows = locate::windows(&data.time, &gain_pos, data.dt, 2.0, 5);
    let conditions: Vec<Condition> =
        locate::conditions(&data.input, d.rate, d.aux, &gain_pos, d.rows).into_iter().take(3).collect();
    let mut params = BTreeMap::new();
    let mut units = BTreeMap::new();
    if let Some(name) = &c.grid_name {
        params.insert(name.clone(), g);
        if name == "b_sat" || name == "b_0" {
            units.insert(name.clone(), xu.to_owned());
        }
    }
    let n_old = reference.terms.len();
    for (t, b) in f.terms.iter().zip(&f.beta).skip(n_old) {
        params.insert(t.name.clone(), *b);
    }
    params.insert("term_rms".into(), term_rms);
    units.insert("term_rms".into(), yu.to_owned());
    let size =
        format!("it changes the {} by {} RMS ({:.1} % of its span)", d.names.1, with_unit(term_rms, yu), 100.0 * share);
    let summary = format!(
        "{}; {size}; held-out R-RMSE {:.2} % -> {:.2} % ({:.0} % lower)",
        what(d),
        100.0 * d.before.r_rmse,
        100.0 * d.after.r_rmse,
        100.0 * d.test.gain
    );
    Finding {
        effect: c.effect.to_owned(),
        summary,
        windows,
        params,
        units,
        heldout_before: d.before,
        heldout_after: d.after,
        conditions,
        evidence: Evidence {
            label: c.label.clone(),
            channel: c.channel.clone(),
            test: d.test,
            term_rms,
            term_share_of_span: share,
            bic_gain: d.bic_gain,
        },
    }
}

/// Which physics, in words.
fn what(d: &Described<'_>) -> String {
    let (c, f, g, dt) = (d.candidate, d.fitted, d.value, d.data.dt);
    let (i, o) = d.names;
    let (xu, yu) = (unit_of(i).unwrap_or(""), unit_of(o).unwrap_or(""));
    let coef = f.beta.get(d.reference.terms.len()).copied().unwrap_or(0.0);
    let ch = c.channel.clone().unwrap_or_default();
    match c.effect {
        "field_lag" => format!(
            "the {o} lags the {i} reading by a first-order lag of {:.2} ms (eddy currents, the fluid's chain-forming time, coil dynamics)",
            1e3 * g
        ),
        "transport_delay" if g >= 0.0 => format!(
            "the {o} responds to the {i} channel {:.2} ms late ({:.1} samples): a timing skew between the channels (ADC pipeline, logger, a filter on one channel)",
            1e3 * g,
            g / dt
        ),
        "transport_delay" => format!(
            "the {i} channel is recorded {:.2} ms late relative to the {o} ({:.1} samples): a timing skew between the channels (ADC pipeline, logger, a filter on one channel)",
            -1e3 * g,
            -g / dt
        ),
        "saturation" => format!(
            "the {i} saturates: the {o} follows b_s·tanh(b/b_s) with b_s = {} (yield stress or steel saturating at high field)",
            with_unit(g, xu)
        ),
        "sensor_offset" => {
            format!("the {i} reading carries a zero offset of {} (Hall offset or remanent field)", with_unit(g, xu))
        }
        "rate_dependence" => format!(
            "the loop changes with the excitation rate beyond the model's linear rate term (a |rate|·rate term, coefficient {coef:.3e})"
        ),
        "asymmetry" => {
            format!("loading and unloading differ by an amount growing with the {i} (δ = {coef:.3e} {yu} per {xu})")
        }
        "thermal_drift" if !ch.is_empty() => format!(
            "the {o} drifts with the temperature channel {ch} (scale {coef:+.3e} per unit, the fluid's viscosity and yield stress falling as it heats)"
        ),
        "thermal_drift" => format!(
            "the {o} drifts with the energy dissipated so far (the fluid heating up: scale {coef:+.3} over the recording)"
        ),
        "slip_speed" => format!("the {o} depends on the slip speed {ch} (viscous shear the field-only model ignores)"),
        "inertia" if !ch.is_empty() => {
            format!("an inertial term in the {o} follows the acceleration from {ch} (coefficient {coef:.3e})")
        }
        "inertia" => format!("an inertial term m·ẍ in the {o} (m = {coef:.3e} {yu} per {xu}/s²; fluid or piston mass)"),
        "aux_dependence" => format!(
            "the {o} depends on the channel {ch}: the model's parameters scale with it (α = {coef:+.3e} per unit of {ch}), and the dependence lags {ch} by a first-order lag of {:.1} ms",
            1e3 * g
        ),
        other => other.to_owned(),
    }
}

/// `v` with 3 decimals (or in scientific notation when very large or small) and its unit.
fn with_unit(v: f64, unit: &str) -> String {
    let s = if v != 0.0 && (v.abs() >= 1e4 || v.abs() < 1e-2) { format!("{v:.3e}") } else { format!("{v:.3}") };
    if unit.is_empty() {
        s
    } else {
        format!("{s} {unit}")
    }
}
