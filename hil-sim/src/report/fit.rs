//! Plots and report sections for fit results: measured vs model over time around the
//! train/held-out boundary, the hysteresis loop with the model's loop over it, the residual
//! over the whole recording, and held-out error per model.

use std::path::Path;

use model_core::control::page::RateSpec;

use super::plot::{self, colour, PlotError, Series, Style};
use super::Report;
use crate::ident::fit::{Dataset, FitResult};
use crate::numerics::number::{num, signed};

/// Axis labels with units, e.g. `("D (cm)", "F (N)")`.
#[derive(Clone, Debug)]
pub struct Labels {
    pub input: String,
    pub output: String,
}

impl Labels {
    /// Labels for channels named `input` and `output`, with the units the names are known
    /// by ([`crate::numerics::units::unit_of`]): `"D"` → `"D (cm)"`.
    pub fn for_channels(input: &str, output: &str) -> Self {
        let with = |n: &str| match crate::numerics::units::unit_of(n) {
            Some(u) => format!("{n} ({u})"),
            None => n.to_owned(),
        };
        Self { input: with(input), output: with(output) }
    }
    /// The output's unit: what the label has in its last parentheses (`"N"`), or `""`.
    pub fn output_unit(&self) -> &str {
        unit_in(&self.output)
    }
    /// The input's unit, as [`Labels::output_unit`].
    pub fn input_unit(&self) -> &str {
        unit_in(&self.input)
    }
    /// The output's name without its unit (`"F"`).
    pub fn output_name(&self) -> &str {
        self.output.rsplit_once(" (").map_or(self.output.as_str(), |(n, _)| n)
    }
}

fn unit_in(label: &str) -> &str {
    label.rsplit_once('(').and_then(|(_, u)| u.strip_suffix(')')).unwrap_or("")
}

/// The rate estimator in words, with its coefficients' units (`unit`: the input's unit).
pub fn describe_rate(spec: &RateSpec, unit: &str) -> String {
    let u = if unit.is_empty() { "1".to_owned() } else { unit.to_owned() };
    match *spec {
        RateSpec::Backward => "backward difference".into(),
        RateSpec::Filtered { fc } => format!("filtered difference, cut-off {} Hz", num(f64::from(fc), 3)),
        RateSpec::Kalman { q, r } => format!(
            "Kalman filter (seed 002), jerk intensity q = {} {u}²/s⁵, measurement variance r = {} {u}²",
            num(f64::from(q), 3),
            num(f64::from(r), 3)
        ),
    }
}

/// How long before the train/held-out boundary the loop plot starts, seconds (short: a
/// loop over seconds of random motion is a tangle).
const LOOP_BEFORE_S: f64 = 0.6;

/// Index range `[a, b)` of the samples between times `t0` and `t1`.
fn span(t: &[f64], t0: f64, t1: f64) -> (usize, usize) {
    let a = t.partition_point(|v| *v < t0);
    let b = t.partition_point(|v| *v < t1).max(a);
    (a, b)
}

/// Flagged stretches as time windows.
fn windows(data: &Dataset) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let mut start: Option<usize> = None;
    for (i, e) in data.excluded.iter().chain(std::iter::once(&false)).enumerate() {
        match (*e, start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                let t = |k: usize| data.time.get(k).copied().unwrap_or(0.0);
                out.push((t(s), t(i.saturating_sub(1))));
                start = None;
            }
            _ => {}
        }
    }
    out
}

/// Write the three plots of one fit into `dir` as `<stem>_{time,loop,residual}.svg` and
/// add them to `report`. The time plot runs from one second before the train/held-out
/// boundary (drawn) to two seconds after it; the loop plot covers the last
/// [`LOOP_BEFORE_S`] of training.
pub fn fit_plots(
    report: &mut Report,
    dir: &Path,
    stem: &str,
    data: &Dataset,
    r: &FitResult,
    labels: &Labels,
) -> Result<(), PlotError> {
    let t = &data.time;
    let t_split = t.get(data.train_end).copied().unwrap_or(0.0);
    let (a, b) = span(t, t_split - 1.0, t_split + 2.0);
    let name = format!("{stem}_time.svg");
    plot::time_series_marked(
        dir.join(&name),
        &format!("{}: measured and replayed output around the train/held-out boundary ({:.2} s)", r.model, t_split),
        "time (s)",
        &labels.output,
        &t[a..b],
        &[
            Series::new("measured", &data.output[a..b]).style(Style::of(colour::MEASURED)),
            Series::new(&format!("{} (f32 replay)", r.model), &r.output[a..b]).style(Style::of(colour::MODEL)),
        ],
        Some(t_split),
    )?;
    report.image(&name, &format!("{}: measured vs model, {:.1}–{:.1} s", r.model, t_split - 1.0, t_split + 2.0));
    let (la, lb) = span(t, t_split - LOOP_BEFORE_S, t_split);
    let name = format!("{stem}_loop.svg");
    // Against the input as the model saw it (shifted by the fitted delay).
    let x = crate::models::alignment::shift(&data.input, r.delay_s / data.dt);
    let x_label = if r.delay_s == 0.0 {
        labels.input.clone()
    } else {
        format!("{} at t {} ms (fitted delay)", labels.input, signed(1e3 * r.delay_s, 2))
    };
    plot::hysteresis_loop(
        dir.join(&name),
        &format!("{}: hysteresis loop, {:.2}–{:.2} s", r.model, t_split - LOOP_BEFORE_S, t_split),
        &x_label,
        &labels.output,
        &x[la..lb],
        &data.output[la..lb],
        &r.output[la..lb],
    )?;
    report.image(&name, &format!("{}: output vs input, measured (grey) and model", r.model));
    let res: Vec<f64> = data.output.iter().zip(&r.output).map(|(y, m)| y - m).collect();
    let name = format!("{stem}_residual.svg");
    plot::residual(
        dir.join(&name),
        &format!("{}: residual (measured − model); shaded: samples the quality checks flagged", r.model),
        &labels.output,
        t,
        &res,
        &windows(data),
        Some(t_split),
    )?;
    report.image(&name, &format!("{}: residual over the whole recording", r.model));
    Ok(())
}

/// One loop plot per model over the whole held-out part (`<stem>_<model>_loop.svg`,
/// at most 4000 points each): the shapes side by side, e.g. an asymmetric loop that the
/// symmetric models (classical PI, Bouc–Wen) cannot follow. Against the input as recorded.
pub fn loop_plots(
    report: &mut Report,
    dir: &Path,
    stem: &str,
    data: &Dataset,
    results: &[FitResult],
    labels: &Labels,
) -> Result<(), PlotError> {
    let (a, b) = (data.train_end.min(data.len()), data.len());
    let every = (b - a).div_ceil(4000).max(1);
    let pick = |v: &[f64]| -> Vec<f64> { v.get(a..b).unwrap_or(&[]).iter().step_by(every).copied().collect() };
    let x = pick(&data.input);
    let y = pick(&data.output);
    for r in results {
        let name = format!("{stem}_{}_loop.svg", r.model);
        plot::hysteresis_loop(
            dir.join(&name),
            &format!("{}: held-out loop (GOF {:.3}, R² {:.4})", r.model, r.heldout.gof, r.heldout.r2),
            &labels.input,
            &labels.output,
            &x,
            &y,
            &pick(&r.output),
        )?;
        report.image(&name, &format!("{}: held-out output vs input, measured (grey) and model", r.model));
    }
    Ok(())
}

/// Bar chart of held-out R-RMSE (%) per model.
pub fn error_bars(report: &mut Report, dir: &Path, stem: &str, results: &[FitResult]) -> Result<(), PlotError> {
    let cats: Vec<String> = results.iter().map(|r| r.model.clone()).collect();
    let held: Vec<f64> = results.iter().map(|r| 100.0 * r.heldout.r_rmse).collect();
    let train: Vec<f64> = results.iter().map(|r| 100.0 * r.train.r_rmse).collect();
    let name = format!("{stem}_errors.svg");
    plot::bars_coloured(
        dir.join(&name),
        "R-RMSE per model (seed 000 eq. 20)",
        "R-RMSE (%)",
        &cats,
        &[("train", &train, Some(colour::TRAIN)), ("held-out", &held, Some(colour::MODEL))],
    )?;
    report.image(&name, "R-RMSE per model, training and held-out parts");
    Ok(())
}

/// The comparison table as report rows, every number with its unit (`unit`: the output's,
/// in the headers). The rate estimator is said once above the table when every model used
/// the same one; the held-out score over unflagged samples gets its own columns when some
/// held-out samples were flagged.
pub fn results_table(report: &mut Report, results: &[FitResult], labels: &Labels) {
    let unit = labels.output_unit();
    let u = |h: &str| if unit.is_empty() { h.to_owned() } else { format!("{h} ({unit})") };
    let same_rate = results.windows(2).all(|w| w[0].rate_choice == w[1].rate_choice);
    if let (true, Some(first)) = (same_rate, results.first()) {
        report.paragraph(&format!(
            "Rate of the input for every model: {}.",
            describe_rate(&first.rate_choice, labels.input_unit())
        ));
    }
    let unflagged = results.iter().any(|r| r.heldout_unflagged.is_some());
    let mut headers: Vec<String> = vec!["model".into(), "free params".into(), "method".into()];
    if !same_rate {
        headers.push("rate estimator".into());
    }
    headers.extend(["delay input / command (ms)".into(), u("train RMSE"), "train R²".into(), u("held-out RMSE")]);
    headers.extend(["held-out R²".into(), "held-out R-RMSE (%)".into(), "held-out GOF".into()]);
    if unflagged {
        headers.extend([u("held-out RMSE, unflagged"), "held-out R², unflagged".into()]);
    }
    headers.extend(["fit (s)".into(), "replay (ns/sample)".into(), "state (B)".into()]);
    let rows: Vec<Vec<String>> = results
        .iter()
        .map(|r| {
            let mut row = vec![r.model.clone(), r.free_params.to_string(), format!("{:?}", r.method).to_lowercase()];
            if !same_rate {
                row.push(describe_rate(&r.rate_choice, labels.input_unit()));
            }
            row.extend([
                format!("{} / {}", signed(1e3 * r.delay_s, 3), signed(1e3 * r.command_delay_s, 3)),
                num(r.train.rmse, 4),
                format!("{:.4}", r.train.r2),
                num(r.heldout.rmse, 4),
                format!("{:.4}", r.heldout.r2),
                format!("{:.2}", 100.0 * r.heldout.r_rmse),
                format!("{:.4}", r.heldout.gof),
            ]);
            if unflagged {
                match &r.heldout_unflagged {
                    Some(m) => row.extend([num(m.rmse, 4), format!("{:.4}", m.r2)]),
                    None => row.extend(["—".into(), "—".into()]),
                }
            }
            row.extend([
                format!("{:.3}", r.fit_seconds),
                format!("{:.1}", r.replay_ns_per_sample),
                r.state_bytes.to_string(),
            ]);
            row
        })
        .collect();
    report.table(&headers, &rows);
}
