//! Stage 5 of a diagnosis, the finding: which physics (in words, with the recording's
//! channel names and units), how big (the fitted values and the RMS of what the term adds,
//! output units and share of the output's span), where (the windows and operating
//! conditions where the drop in squared error concentrates, [`super::locate`]) and the
//! held-out error before and after.

use std::collections::BTreeMap;

use super::acting::Acting;
use super::augment::Fitted;
use super::candidates::{Candidate, DIRECTION_SQUARED_TERM, DIRECTION_TERM, LOADING_TERM};
use super::diagnosis::{Evidence, Finding, Tested};
use super::lag_or_delay::Mixture;
use super::locate::{self, Condition};
use super::physical::Reading;
use super::replicate::Replication;
use super::significance::Test;
use crate::ident::fit::Dataset;
use crate::numerics::metrics::Metrics;

/// Everything a finding is described from.
pub struct Described<'a> {
    pub data: &'a Dataset,
    pub candidate: &'a Candidate,
    /// What the candidate stands for as fitted ([`super::physical::reading`]).
    pub reading: &'a Reading,
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
    /// The reversed split, when the tail alone did not settle it.
    pub replication: Option<Replication>,
    /// The field lag and the delay given together, when that settled a tie between them.
    pub lag_or_delay: Option<Mixture>,
    /// The split where it acts, when the tail barely excited it.
    pub acting: Option<Acting>,
    pub bic_gain: f64,
    /// Span (peak to peak) of the output on the held-out rows.
    pub y_span: f64,
    /// The input's rate and the auxiliary channels (name, values), for the conditions.
    pub rate: &'a [f64],
    pub aux: &'a [(&'a str, &'a [f64])],
    /// Rows the term's size and the conditions are taken over.
    pub rows: &'a [usize],
    /// Sample indices where runs of a multi-run recording join.
    pub boundaries: &'a [usize],
    /// The candidate that does nearly as well, when the evidence is weak.
    pub runner_up: Option<String>,
}

/// When the kept candidate's evidence is weak (t below twice the threshold, or another
/// effect's significant candidate within 5 % of its held-out error), that candidate in
/// words: its effect and term.
pub fn runner_up(tested: &[Tested], round: usize, kept: &str, test: &Test, after_r_rmse: f64) -> Option<String> {
    let other = tested
        .iter()
        .filter(|t| t.round == round && t.effect != kept && t.impossible.is_none() && t.test.significant)
        .min_by(|a, b| a.heldout_r_rmse_after.total_cmp(&b.heldout_r_rmse_after))?;
    let close = other.heldout_r_rmse_after <= 1.05 * after_r_rmse;
    (close || test.t < 2.0 * super::significance::T_MIN).then(|| format!("{} ({})", other.effect, other.label))
}

/// Where the windows sit on run boundaries or flagged samples, in words (empty when not).
fn caveats(data: &Dataset, windows: &[(f64, f64)], boundaries: &[usize]) -> String {
    let near = |a: f64, b: f64, t: f64| t >= a - 0.05 && t <= b + 0.05;
    let on_boundary: Vec<String> = boundaries
        .iter()
        .filter_map(|&k| data.time.get(k))
        .filter(|&&t| windows.iter().any(|&(a, b)| near(a, b, t)))
        .map(|t| format!("{t:.2} s"))
        .collect();
    let flagged = windows.iter().any(|&(a, b)| data.time.iter().zip(&data.excluded).any(|(&t, &x)| x && near(a, b, t)));
    let mut out = String::new();
    if !on_boundary.is_empty() {
        out += &format!(
            "; its windows sit on the joins between runs (at {}): check that the term is not the join itself",
            on_boundary.join(", ")
        );
    }
    if flagged {
        out += "; its windows touch samples the quality check flagged: check the recording there";
    }
    out
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
        if let Some(u) = grid_unit(name, (xu, yu)) {
            units.insert(name.clone(), u.to_owned());
        }
    }
    let n_old = reference.terms.len();
    for (t, b) in f.terms.iter().zip(&f.beta).skip(n_old) {
        params.insert(t.name.clone(), *b);
        if let Some(u) = coefficient_unit(&t.name, d.names, c.channel.as_deref()) {
            units.insert(t.name.clone(), u);
        }
    }
    params.insert("term_rms".into(), term_rms);
    units.insert("term_rms".into(), yu.to_owned());
    let size = format!(
        "it changes the {} by {} RMS ({:.1} % of its span)",
        d.names.1,
        with_unit(term_rms, &unit_or(d.names.1)),
        100.0 * share
    );
    let weak =
        d.runner_up.as_ref().map(|r| format!("; the evidence is weak: the runner-up is {r}")).unwrap_or_default();
    let again = d
        .replication
        .map(|r| {
            let why = if d.test.significant {
                format!(
                    "another effect's term came within {:.0} % of it on the held-out tail",
                    100.0 * super::replicate::NEAR
                )
            } else {
                "the held-out tail alone did not settle it".to_owned()
            };
            format!(
                " ({why}; refitted with the head held out instead, the head's error is {:.0} % lower, {:.0} % over both \
                 held-out parts)",
                100.0 * r.head.gain,
                100.0 * r.both.gain
            )
        })
        .unwrap_or_default();
    let both = d.lag_or_delay.map(|m| mixture_clause(&m, d.reading.effect)).unwrap_or_default();
    let acts = d.acting.map(|a| acting_clause(&a)).unwrap_or_default();
    let summary = format!(
        "{}; {size}; held-out R-RMSE {:.2} % -> {:.2} % ({}){again}{both}{acts}{weak}{}",
        what(d),
        100.0 * d.before.r_rmse,
        100.0 * d.after.r_rmse,
        // Only a term kept where it acts ([`super::acting`]) can predict the tail worse.
        if d.test.gain >= 0.0 {
            format!("{:.0} % lower", 100.0 * d.test.gain)
        } else {
            format!("{:.0} % higher on the tail", -100.0 * d.test.gain)
        },
        caveats(data, &windows, d.boundaries)
    );
    Finding {
        effect: d.reading.effect.to_owned(),
        summary,
        windows,
        params,
        units,
        heldout_before: d.before,
        heldout_after: d.after,
        conditions,
        evidence: Evidence {
            label: d.reading.label.clone(),
            channel: c.channel.clone(),
            test: d.test,
            replication: d.replication,
            lag_or_delay: d.lag_or_delay,
            acting: d.acting,
            term_rms,
            term_share_of_span: share,
            bic_gain: d.bic_gain,
        },
        runner_up: d.runner_up.clone(),
    }
}

/// Why and how a term the held-out tail barely excites was kept, in words.
fn acting_clause(a: &Acting) -> String {
    format!(
        " (the held-out tail barely excites it: there it changes the prediction by {:.0} % of what it changes over \
         the training part; refitted with {:.2}-{:.2} s held out instead in interleaved pieces, where it acts most, that \
         stretch's R-RMSE is {:.2} % -> {:.2} %, {:.0} % lower)",
        100.0 * a.tail_share,
        a.from_s,
        a.to_s,
        100.0 * a.r_rmse_before,
        100.0 * a.r_rmse_after,
        100.0 * a.test.gain
    )
}

/// How a tie between a field lag and a delay of the torque was settled, in words.
fn mixture_clause(m: &Mixture, effect: &str) -> String {
    let rival = if effect == "field_lag" { "a delay of the torque" } else { "a lag of the field" };
    let settled = if m.side().is_some() { "" } else { ", which does not tell them apart" };
    format!(
        " (it came within {:.0} % of {rival} on the held-out tail; given both at once, the training error is least \
         with {:.0} % of the {} delay{settled})",
        100.0 * super::replicate::NEAR,
        100.0 * m.best_share,
        with_unit(1e3 * m.delay_s, "ms")
    )
}

/// A direction term read as the loop narrowing at high level ([`super::physical::reading`]),
/// in words: `coef` its coefficient, the input's name and the input's and output's units.
fn narrowing(d: &Described<'_>, coef: f64, (i, xu, yu): (&str, &str, &str)) -> String {
    let term = d.fitted.terms.get(d.reference.terms.len()).map_or("", |t| t.name.as_str());
    let fall = with_unit(-coef, yu);
    let how = match term {
        LOADING_TERM => format!("the loading branch falls by {fall} per {xu} above its floor"),
        DIRECTION_SQUARED_TERM => {
            format!(
                "the loading/unloading difference falls by {fall} per ({xu})² away from its mean, towards both ends"
            )
        }
        _ => format!("the loading/unloading difference falls by {fall} per {xu}"),
    };
    format!(
        "the loop between loading and unloading narrows as the {i} grows ({how}): the fluid's yield stress levelling \
         off at high field"
    )
}

/// Which physics, in words.
fn what(d: &Described<'_>) -> String {
    let (c, f, g, dt) = (d.candidate, d.fitted, d.value, d.data.dt);
    let (i, o) = d.names;
    let (xu, yu) = (unit_or(i), unit_or(o));
    let coef = f.beta.get(d.reference.terms.len()).copied().unwrap_or(0.0);
    let coef2 = f.beta.get(d.reference.terms.len() + 1).copied().unwrap_or(0.0);
    let ch = c.channel.clone().unwrap_or_default();
    match d.reading.effect {
        "saturation" if d.reading.narrowing => narrowing(d, coef, (i, &xu, &yu)),
        "field_lag" if c.label.contains("two-pole") => format!(
            "the {o} lags the {i} reading through two first-order lags of {:.2} ms each ({:.2} ms in all: a field diffusing through the discs, or eddy currents behind a coil lag)",
            0.5e3 * g,
            1e3 * g
        ),
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
        "saturation" if c.grid_name.as_deref() == Some("t_sat") => format!(
            "the {o} levels off at high level whatever the {i} does (the fluid's yield stress saturating): above its floor it follows u/√(1 + (u/T_s)²) of the model's, T_s = {} ({} of that map{})",
            with_unit(g, &yu),
            with_unit(100.0 * coef, "%"),
            yield_equivalent(g, coef)
                .map(|t| format!("; at small u the map itself at T_s/√k = {}", with_unit(t, &yu)))
                .unwrap_or_default()
        ),
        "saturation" if c.label.contains("knee") => format!(
            "the {i} saturates with a sharp knee: the {o} follows b/(1 + (b/b_s)⁴)^¼ with b_s = {} (steel saturating over a narrow range of the field)",
            with_unit(g, &xu)
        ),
        "saturation" => format!(
            "the {i} saturates: the {o} follows b_s·tanh(b/b_s) with b_s = {} (yield stress or steel saturating at high field)",
            with_unit(g, &xu)
        ),
        "sensor_offset" => {
            format!("the {i} reading carries a zero offset of {} (Hall offset or remanent field)", with_unit(g, &xu))
        }
        "rate_dependence" if c.label.contains("rate³") => format!(
            "the loop changes with the excitation rate beyond the model's linear rate term (a rate³ term, coefficient {} per ({xu}/s)³)",
            with_unit(coef, &yu)
        ),
        "rate_dependence" if c.label.contains("frequency") => format!(
            "the damping grows with the excitation frequency beyond the model's linear rate term (c·(f/f̄ − 1)·rate, c = {} per ({xu}/s), the frequency f averaged over the last {:.2} s)",
            with_unit(coef, &yu),
            g
        ),
        "rate_dependence" => format!(
            "the loop changes with the excitation rate beyond the model's linear rate term (a |rate|·rate term, coefficient {} per ({xu}/s)²)",
            with_unit(coef, &yu)
        ),
        "asymmetry" if c.label.contains("squared") => format!(
            "loading and unloading differ by an amount growing with the square of the {i} (δ₂ = {} per ({xu})²)",
            with_unit(coef, &yu)
        ),
        "asymmetry" if c.label.starts_with("loading branch") => format!(
            "the loading branch alone is lifted by an amount growing with the {i} above its floor (δ_l = {} per {xu})",
            with_unit(coef, &yu)
        ),
        "asymmetry" => {
            format!("loading and unloading differ by an amount growing with the {i} (δ = {} per {xu})", with_unit(coef, &yu))
        }
        "thermal_drift" if !ch.is_empty() => format!(
            "the {o} drifts with the temperature channel {ch} (scale {} per {}, offset {} per {}: the fluid's viscosity and yield stress falling as it heats); or a slow offset drift",
            with_unit(100.0 * coef, "%"),
            unit_or(&ch),
            with_unit(coef2, &yu),
            unit_or(&ch)
        ),
        "thermal_drift" => format!(
            "the {o} drifts with the energy dissipated so far (the fluid heating up: scale {} and offset {} over the recording); or a slow offset drift",
            with_unit(100.0 * coef, "%"),
            with_unit(coef2, &yu)
        ),
        "slip_speed" => format!(
            "the {o} depends on the slip speed {ch} (viscous shear the field-only model ignores): {} per ({}), and {} per ({}) at the largest {i}",
            with_unit(coef, &yu),
            unit_or(&ch),
            with_unit(coef2, &yu),
            unit_or(&ch)
        ),
        "inertia" if !ch.is_empty() => {
            let measured = c.label.contains("measured acceleration");
            let per = if measured { unit_or(&ch) } else { format!("{}/s", unit_or(&ch)) };
            format!("an inertial term in the {o} follows the acceleration from {ch} ({})", inertia(coef, &yu, &per))
        }
        "inertia" => {
            format!("an inertial term m·ẍ in the {o} (m = {} per ({xu}/s²); fluid or piston mass)", with_unit(coef, &yu))
        }
        "aux_dependence" => format!(
            "the {o} depends on the channel {ch}: the model's parameters scale with it (α = {} per {}), and the dependence lags {ch} by a first-order lag of {:.1} ms",
            with_unit(100.0 * coef, "%"),
            unit_or(&ch),
            1e3 * g
        ),
        other => other.to_owned(),
    }
}

/// The unit of a candidate's grid value `name` (`xu`, `yu`: the input's and the output's
/// units): a saturation level or offset of the input in the input's, a torque saturation
/// level in the output's, a time (`…_s`) in s; `None` for any other.
pub fn grid_unit<'a>(name: &str, (xu, yu): (&'a str, &'a str)) -> Option<&'a str> {
    match name {
        "b_sat" | "b_0" => Some(xu),
        "t_sat" => Some(yu),
        n if n.ends_with("_s") => Some("s"),
        _ => None,
    }
}

/// The unit of a term's coefficient `name` (input and output channel names, the channel
/// the term uses), `None` for a dimensionless scale (`alpha`, `kappa_…`).
fn coefficient_unit(name: &str, (i, o): (&str, &str), ch: Option<&str>) -> Option<String> {
    let (xu, yu) = (unit_or(i), unit_or(o));
    let cu = ch.map(unit_or).unwrap_or_default();
    Some(match name {
        "c_rate" => format!("{yu} per ({xu}/s)²"),
        "c_rate3" => format!("{yu} per ({xu}/s)³"),
        "c_freq" => format!("{yu} per ({xu}/s)"),
        DIRECTION_TERM | LOADING_TERM | "k_input" => format!("{yu} per {xu}"),
        DIRECTION_SQUARED_TERM => format!("{yu} per ({xu})²"),
        "m" if ch.is_some() => format!("{yu} per ({cu})"),
        "m" => format!("{yu} per ({xu}/s²)"),
        "j" if yu == "N·m" && cu == "rad/s" => "kg·m²".to_owned(),
        "j" => format!("{yu} per ({cu}/s)"),
        "c_omega" | "c_omega_field" => format!("{yu} per ({cu})"),
        "offset" | "offset_per_unit" => format!("{yu} per {cu}"),
        "offset_energy" => yu,
        "kappa_per_unit" | "alpha" => format!("1 per {cu}"),
        _ => return None,
    })
}

/// The unit of channel `name`, or `unit of <name>` when it is not a known one.
fn unit_or(name: &str) -> String {
    unit_of(name).map_or_else(|| format!("unit of {name}"), str::to_owned)
}

/// An inertia coefficient in words (`chu`: the unit of the acceleration it multiplies):
/// `kg·m²` for a torque against rad/s², `kg` for a force against m/s², else the output's
/// unit per the acceleration's.
fn inertia(coef: f64, yu: &str, chu: &str) -> String {
    match (yu, chu) {
        ("N·m", "rad/s/s") => format!("J = {}", with_unit(coef, "kg·m²")),
        ("N", "m/s/s" | "m/s²") => format!("m = {}", with_unit(coef, "kg")),
        _ => format!("coefficient {} per ({chu})", with_unit(coef, yu)),
    }
}

/// The level `T_s/√k` at which the map itself, `u/√(1 + (u/T)²)`, compresses a small `u` as the
/// yield-stress term `u + k·(u/√(1 + (u/T_s)²) − u)` does (both `u − u³/(2T²)` to third order);
/// `None` unless `k > 0`.
fn yield_equivalent(t_sat: f64, k: f64) -> Option<f64> {
    (k > 0.0 && t_sat > 0.0).then(|| t_sat / k.sqrt())
}

/// `v` with 4 significant digits (a power of ten written out, never e-notation) and its unit.
fn with_unit(v: f64, unit: &str) -> String {
    crate::numerics::number::with_unit(v, 4, unit)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_yield_stress_term_reads_as_the_map_at_its_equivalent_level() {
        let sat = |u: f64, t: f64| u / (1.0 + (u / t).powi(2)).sqrt();
        for (t_sat, k) in [(108.4, 20.99), (5.0, 0.5), (40.0, 3.0)] {
            let t = yield_equivalent(t_sat, k).unwrap();
            for share in [0.05, 0.1, 0.2] {
                let u = share * t;
                let term = u + k * (sat(u, t_sat) - u);
                // Equal to third order: the difference is of fifth order, (share)⁴ of u.
                assert!((term - sat(u, t)).abs() <= 2.0 * share.powi(4) * u, "{t_sat} {k} {share}");
            }
        }
        assert_eq!(yield_equivalent(10.0, -0.2), None);
        assert_eq!(yield_equivalent(10.0, 0.0), None);
    }
}
