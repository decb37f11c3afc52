//! Lines over time with a legend (e.g. measured and model output), each decimated to its
//! M4 envelope (per pixel column: first, lowest, highest, last point), optionally with the
//! train/held-out boundary drawn as a dashed line.

use std::path::Path;

use plotters::style::Color;

use super::canvas::{boundary, chart, draw_line, legend_strip, mesh, render, split_legend, Mark};
use super::decimate::envelope;
use super::range::{pad, range_of};
use super::style::{colour, rgb, Style};
use super::{no_finite, nonempty, same_len, PlotError, PLOT_W};

/// One line of a [`time_series`] plot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Series<'a> {
    /// Legend entry.
    pub name: &'a str,
    /// One value per time sample.
    pub values: &'a [f64],
    pub style: Style,
}

impl<'a> Series<'a> {
    /// A series with the default style (next palette colour, 2 px, opacity 0.85 so that
    /// overlapping lines stay visible).
    pub fn new(name: &'a str, values: &'a [f64]) -> Self {
        Self { name, values, style: Style::default() }
    }
    pub fn style(mut self, style: Style) -> Self {
        self.style = style;
        self
    }
}

/// Lines over time with a legend, e.g. measured and model output. `t` is the common time
/// axis; each series has one value per `t`.
pub fn time_series(
    path: impl AsRef<Path>,
    title: &str,
    x_label: &str,
    y_label: &str,
    t: &[f64],
    series: &[Series<'_>],
) -> Result<(), PlotError> {
    time_series_marked(path, title, x_label, y_label, t, series, None)
}

/// [`time_series`] with a dashed line at `train_end` (s), the end of the training part.
pub fn time_series_marked(
    path: impl AsRef<Path>,
    title: &str,
    x_label: &str,
    y_label: &str,
    t: &[f64],
    series: &[Series<'_>],
    train_end: Option<f64>,
) -> Result<(), PlotError> {
    let path = path.as_ref();
    nonempty("time axis", t.len())?;
    if series.is_empty() {
        return Err(PlotError::Empty { what: "series list".into() });
    }
    for s in series {
        same_len(s.name, s.values.len(), t.len())?;
    }
    let xr = range_of(t.iter().copied()).ok_or_else(|| no_finite("time axis"))?;
    let lines: Vec<Vec<Vec<(f64, f64)>>> = series.iter().map(|s| envelope(t, s.values, xr.clone(), PLOT_W)).collect();
    let yr = range_of(lines.iter().flatten().flatten().map(|p| p.1)).ok_or_else(|| no_finite("series values"))?;
    render(path, |root| {
        let (area, strip) = split_legend(root);
        let mut chart = chart(&area, title, pad(xr.clone(), 0.0), pad(yr, 0.05))?;
        mesh(&mut chart, x_label, y_label)?;
        let mut entries = Vec::new();
        for (i, (s, segs)) in series.iter().zip(&lines).enumerate() {
            draw_line(&mut chart, segs, s.style.shape(i))?;
            entries.push((s.name.to_owned(), Mark::Line(s.style.shape(i))));
        }
        if let Some(te) = train_end.filter(|v| xr.contains(v)) {
            let mark = rgb(colour::BOUNDARY).stroke_width(2);
            boundary(&mut chart, &area, te, "train ← | → held-out", mark)?;
            entries.push(("end of training".to_owned(), Mark::Dashed(mark)));
        }
        legend_strip(&strip, &entries)
    })
}
