//! A residual (measured − model) over time, with shaded time windows (e.g. samples the
//! quality checks flagged) and a marker at the end of the training part.

use std::path::Path;

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::canvas::{chart, draw_err, draw_line, legend, mesh, render};
use super::decimate::envelope;
use super::range::{headroom, pad, range_of};
use super::style::{FONT, TICK_PX};
use super::{no_finite, nonempty, same_len, PlotError, PLOT_W};

/// Residual (measured − model) over time `t` (s), with optional shaded time windows
/// `(start, end)` and a vertical marker at `train_end` (end of the training part).
/// `y_label` names the residual with its unit, e.g. `"force residual (N)"`.
pub fn residual(
    path: impl AsRef<Path>,
    title: &str,
    y_label: &str,
    t: &[f64],
    residual: &[f64],
    windows: &[(f64, f64)],
    train_end: Option<f64>,
) -> Result<(), PlotError> {
    let path = path.as_ref();
    nonempty("time axis", t.len())?;
    same_len("residual", residual.len(), t.len())?;
    let xr = range_of(t.iter().copied()).ok_or_else(|| no_finite("time axis"))?;
    let segs = envelope(t, residual, xr.clone(), PLOT_W);
    let yr = range_of(segs.iter().flatten().map(|p| p.1).chain([0.0])).ok_or_else(|| no_finite("residual"))?;
    let entries = 1 + usize::from(!windows.is_empty()) + usize::from(train_end.is_some());
    let (xr, yr) = (pad(xr, 0.0), headroom(pad(yr, 0.05), entries));
    render(path, |root| {
        let mut chart = chart(root, title, xr.clone(), yr.clone())?;
        mesh(&mut chart, "time (s)", y_label)?;
        // Windows under the line, clipped to the axis.
        let shade = RGBColor(230, 159, 0).mix(0.25).filled();
        let rects: Vec<_> = windows
            .iter()
            .filter(|(a, b)| a.is_finite() && b.is_finite())
            .map(|&(a, b)| (a.min(b).max(xr.start), a.max(b).min(xr.end)))
            .filter(|(a, b)| a < b)
            .map(|(a, b)| Rectangle::new([(a, yr.start), (b, yr.end)], shade))
            .collect();
        if !rects.is_empty() {
            chart
                .draw_series(rects)
                .map_err(draw_err)?
                .label("windows")
                .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 20, y + 6)], shade));
        }
        let zero = BLACK.mix(0.5).stroke_width(1);
        chart.draw_series(LineSeries::new([(xr.start, 0.0), (xr.end, 0.0)], zero)).map_err(draw_err)?;
        draw_line(&mut chart, &segs, RGBColor(0, 114, 178).stroke_width(1), Some("residual"))?;
        if let Some(te) = train_end.filter(|v| v.is_finite() && xr.contains(v)) {
            let mark = RGBColor(200, 0, 0).stroke_width(2);
            chart
                .draw_series(DashedLineSeries::new([(te, yr.start), (te, yr.end)], 8, 5, mark))
                .map_err(draw_err)?
                .label("end of training")
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], mark));
            let font = (FONT, TICK_PX).into_font().color(&RGBColor(200, 0, 0));
            let (px, py) = chart.backend_coord(&(te, yr.start));
            root.draw(&Text::new("train ← | → held-out", (px, py - 6), font.pos(Pos::new(HPos::Center, VPos::Bottom))))
                .map_err(draw_err)?;
        }
        legend(&mut chart)
    })
}
