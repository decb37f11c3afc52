//! The shared canvas: an SVG picture of [`SIZE`] written to a file, a chart with its
//! caption, axes (mesh, tick labels with as many decimals as the span needs) and legend,
//! and lines drawn as runs of finite points.

use std::ops::Range;
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::style::{CAPTION_PX, FONT, LABEL_PX, TICK_PX};
use super::{PlotError, SIZE};

pub(super) type Chart<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

pub(super) fn render<F>(path: &Path, draw: F) -> Result<(), PlotError>
where
    F: FnOnce(&DrawingArea<SVGBackend<'_>, Shift>) -> Result<(), String>,
{
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err).map_err(|msg| PlotError::Draw { path: path.into(), msg })?;
        draw(&root).map_err(|msg| PlotError::Draw { path: path.into(), msg })?;
        root.present().map_err(|e| PlotError::Draw { path: path.into(), msg: e.to_string() })?;
    }
    Ok(crate::io::output::write(path, svg)?)
}

pub(super) fn chart<'a, 'b>(
    root: &'a DrawingArea<SVGBackend<'b>, Shift>,
    title: &str,
    xr: Range<f64>,
    yr: Range<f64>,
) -> Result<Chart<'a, 'b>, String> {
    ChartBuilder::on(root)
        .caption(title, (FONT, CAPTION_PX))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(80)
        .build_cartesian_2d(xr, yr)
        .map_err(draw_err)
}

pub(super) fn mesh<'a, 'b: 'a>(chart: &mut Chart<'a, 'b>, x_label: &str, y_label: &str) -> Result<(), String> {
    let (xr, yr) = (chart.x_range(), chart.y_range());
    let fx = move |v: &f64| tick(*v, xr.end - xr.start);
    let fy = move |v: &f64| tick(*v, yr.end - yr.start);
    chart
        .configure_mesh()
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .x_desc(x_label)
        .y_desc(y_label)
        .axis_desc_style((FONT, LABEL_PX))
        .label_style((FONT, TICK_PX))
        .x_labels(10)
        .y_labels(8)
        .light_line_style(BLACK.mix(0.05))
        .bold_line_style(BLACK.mix(0.12))
        .draw()
        .map_err(draw_err)
}

pub(super) fn legend<'a, 'b: 'a>(chart: &mut Chart<'a, 'b>) -> Result<(), String> {
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font((FONT, TICK_PX + 1))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.4))
        .draw()
        .map_err(draw_err)
}

/// Draw the segments of one line; the legend entry (if any) goes on the first segment
/// (an empty one is drawn when there are none, so the entry is always there).
pub(super) fn draw_line<'a, 'b: 'a>(
    chart: &mut Chart<'a, 'b>,
    segs: &[Vec<(f64, f64)>],
    style: ShapeStyle,
    name: Option<&str>,
) -> Result<(), String> {
    let empty = Vec::new();
    let mut iter = segs.iter();
    let first = iter.next().unwrap_or(&empty);
    let ann = chart.draw_series(LineSeries::new(first.iter().copied(), style)).map_err(draw_err)?;
    if let Some(name) = name {
        ann.label(name).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style.stroke_width(2)));
    }
    for seg in iter {
        chart.draw_series(LineSeries::new(seg.iter().copied(), style)).map_err(draw_err)?;
    }
    Ok(())
}

/// A tick label with as many decimals as the axis span needs (no "3000.0", no "-0.0").
pub(super) fn tick(v: f64, span: f64) -> String {
    let decimals =
        if span > 0.0 && span.is_finite() { (2.0 - (span / 8.0).log10().floor()).clamp(0.0, 9.0) } else { 3.0 };
    let magnitude = v.abs();
    if magnitude <= span * 1e-9 {
        return "0".to_owned();
    }
    if magnitude != 0.0 && !(1e-4..1e7).contains(&magnitude) && span < 1e300 {
        return format!("{v:.2e}");
    }
    let s = format!("{v:.*}", decimals as usize);
    let s = if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.').to_owned() } else { s };
    if s == "-0" {
        "0".to_owned()
    } else {
        s
    }
}

pub(super) fn draw_err<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}
