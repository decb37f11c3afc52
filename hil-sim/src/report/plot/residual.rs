//! A residual (measured − model) over time, with shaded time windows (e.g. samples the
//! quality checks flagged) and a marker at the end of the training part.

use std::path::Path;

use plotters::prelude::*;

use super::canvas::{boundary, chart, draw_err, draw_line, legend_strip, mesh, render, split_legend, Mark};
use super::decimate::envelope;
use super::range::{pad, range_of};
use super::style::{colour, rgb};
use super::{no_finite, nonempty, same_len, PlotError, PLOT_W};

/// Residual (measured − model) over time `t` (s), with optional shaded time windows
/// `(start, end)` (samples the quality checks flagged) and a vertical marker at `train_end`
/// (end of the training part). `y_label` names the residual with its unit, e.g.
/// `"force residual (N)"`.
pub fn residual(
    path: impl AsRef<Path>,
    title: &str,
    y_label: &str,
    t: &[f64],
    residual: &[f64],
    windows: &[(f64, f64)],
    train_end: Option<f64>,
) -> Result<(), PlotError> {
    residual_shaded(path, title, y_label, t, residual, (windows, "flagged by the quality checks"), train_end)
}

/// [`residual`] with the legend's name for the shaded windows (e.g. "where the findings bite").
pub fn residual_shaded(
    path: impl AsRef<Path>,
    title: &str,
    y_label: &str,
    t: &[f64],
    residual: &[f64],
    (windows, windows_are): (&[(f64, f64)], &str),
    train_end: Option<f64>,
) -> Result<(), PlotError> {
    let path = path.as_ref();
    nonempty("time axis", t.len())?;
    same_len("residual", residual.len(), t.len())?;
    let xr = range_of(t.iter().copied()).ok_or_else(|| no_finite("time axis"))?;
    let segs = envelope(t, residual, xr.clone(), PLOT_W);
    let yr = range_of(segs.iter().flatten().map(|p| p.1).chain([0.0])).ok_or_else(|| no_finite("residual"))?;
    let (xr, yr) = (pad(xr, 0.0), pad(yr, 0.05));
    render(path, |root| {
        let (area, strip) = split_legend(root);
        let mut chart = chart(&area, title, xr.clone(), yr.clone())?;
        mesh(&mut chart, "time (s)", y_label)?;
        let mut entries = Vec::new();
        // Windows under the line, clipped to the axis.
        let shade = rgb(colour::FLAGGED).mix(0.3).filled();
        let rects: Vec<_> = windows
            .iter()
            .filter(|(a, b)| a.is_finite() && b.is_finite())
            .map(|&(a, b)| (a.min(b).max(xr.start), a.max(b).min(xr.end)))
            .filter(|(a, b)| a < b)
            .map(|(a, b)| Rectangle::new([(a, yr.start), (b, yr.end)], shade))
            .collect();
        if !rects.is_empty() {
            chart.draw_series(rects).map_err(draw_err)?;
            entries.push((windows_are.to_owned(), Mark::Patch(shade)));
        }
        let zero = BLACK.mix(0.5).stroke_width(1);
        chart.draw_series(LineSeries::new([(xr.start, 0.0), (xr.end, 0.0)], zero)).map_err(draw_err)?;
        let line = rgb(colour::RESIDUAL).stroke_width(1);
        draw_line(&mut chart, &segs, line)?;
        entries.insert(0, ("residual".to_owned(), Mark::Line(line)));
        if let Some(te) = train_end.filter(|v| v.is_finite() && xr.contains(v)) {
            let mark = rgb(colour::BOUNDARY).stroke_width(2);
            boundary(&mut chart, &area, te, "train ← | → held-out", mark)?;
            entries.push(("end of training".to_owned(), Mark::Dashed(mark)));
        }
        legend_strip(&strip, &entries)
    })
}
