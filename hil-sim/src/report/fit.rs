//! Plots and report sections for fit results: measured vs model over time around the
//! train/held-out boundary, the hysteresis loop with the model's loop over it, the residual
//! over the whole recording, and held-out error per model.

use std::path::Path;

use super::plot::{self, PlotError, Series, Style};
use super::Report;
use crate::ident::fit::{Dataset, FitResult};

/// Axis labels with units, e.g. `("D (cm)", "F (N)")`.
#[derive(Clone, Debug)]
pub struct Labels {
    pub input: String,
    pub output: String,
}

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
/// add them to `report`. The time and loop plots show the held-out part's motion: from one
/// second before the boundary to two seconds after it.
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
    plot::time_series(
        dir.join(&name),
        &format!("{}: measured and replayed output around the train/held-out boundary ({:.2} s)", r.model, t_split),
        "time (s)",
        &labels.output,
        &t[a..b],
        &[
            Series::new("measured", &data.output[a..b]).style(Style::rgb(90, 90, 90).width(2)),
            Series::new(&format!("{} (f32 replay)", r.model), &r.output[a..b]),
        ],
    )?;
    report.image(&name, &format!("{}: measured vs model, {:.1}–{:.1} s", r.model, t_split - 1.0, t_split + 2.0));
    let (la, lb) = span(t, t_split - 1.0, t_split + 0.5);
    let name = format!("{stem}_loop.svg");
    // Against the input as the model saw it (shifted by the fitted delay).
    let x = crate::models::alignment::shift(&data.input, r.delay_s / data.dt);
    let x_label = if r.delay_s == 0.0 {
        labels.input.clone()
    } else {
        format!("{} at t {:+.2} ms (fitted delay)", labels.input, 1e3 * r.delay_s)
    };
    plot::hysteresis_loop(
        dir.join(&name),
        &format!("{}: hysteresis loop, {:.1}–{:.1} s", r.model, t_split - 1.0, t_split + 0.5),
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
    plot::bars(
        dir.join(&name),
        "R-RMSE per model (seed 000 eq. 20)",
        "R-RMSE (%)",
        &cats,
        &[("train", train), ("held-out", held)],
    )?;
    report.image(&name, "R-RMSE per model, training and held-out parts");
    Ok(())
}

/// The comparison table as report rows.
pub fn results_table(report: &mut Report, results: &[FitResult]) {
    let rows: Vec<Vec<String>> = results
        .iter()
        .map(|r| {
            vec![
                r.model.clone(),
                r.free_params.to_string(),
                format!("{:?}", r.method).to_lowercase(),
                r.rate.clone(),
                format!("{:+.3} / {:+.3}", 1e3 * r.delay_s, 1e3 * r.command_delay_s),
                format!("{:.2}", r.train.rmse),
                format!("{:.4}", r.train.r2),
                format!("{:.2}", r.heldout.rmse),
                format!("{:.4}", r.heldout.r2),
                format!("{:.2} %", 100.0 * r.heldout.r_rmse),
                format!("{:.4}", r.heldout.gof),
                format!("{:.3}", r.fit_seconds),
                format!("{:.1}", r.replay_ns_per_sample),
                r.state_bytes.to_string(),
            ]
        })
        .collect();
    report.table(
        &[
            "model",
            "free params",
            "method",
            "rate estimator",
            "delay input / command (ms)",
            "train RMSE",
            "train R²",
            "held-out RMSE",
            "held-out R²",
            "held-out R-RMSE",
            "held-out GOF",
            "fit (s)",
            "replay (ns/sample)",
            "state (B)",
        ],
        &rows,
    );
}
