//! The shared canvas: an SVG picture of [`SIZE`] written to a file, a chart with its
//! caption, axes (mesh, tick labels with as many decimals as the span needs), a legend in
//! a strip under the chart (never over the data or the shaded windows), and lines drawn as
//! runs of finite points.

use std::ops::Range;
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use plotters::style::text_anchor::{HPos, Pos, VPos};

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
    render_sized(path, SIZE, draw)
}

/// [`render`] with a picture size of its own (e.g. bar charts that grow with their rows).
pub(super) fn render_sized<F>(path: &Path, size: (u32, u32), draw: F) -> Result<(), PlotError>
where
    F: FnOnce(&DrawingArea<SVGBackend<'_>, Shift>) -> Result<(), String>,
{
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
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

/// Height of the legend strip under a chart, pixels.
pub(super) const LEGEND_H: u32 = 34;

/// What a legend entry shows before its name.
#[derive(Clone, Copy, Debug)]
pub(super) enum Mark {
    Line(ShapeStyle),
    Dashed(ShapeStyle),
    /// A filled box (shaded windows, bars).
    Patch(ShapeStyle),
}

/// The chart's area and the legend strip under it.
pub(super) fn split_legend<'b>(
    root: &DrawingArea<SVGBackend<'b>, Shift>,
) -> (DrawingArea<SVGBackend<'b>, Shift>, DrawingArea<SVGBackend<'b>, Shift>) {
    let h = root.dim_in_pixel().1;
    root.split_vertically(h.saturating_sub(LEGEND_H))
}

/// Width of `text` at a plotters font size, pixels (an upper estimate for sans-serif:
/// the SVG font size is `font_px / 1.24`, an average glyph 0.6 of it).
pub(super) fn text_px(text: &str, font_px: u32) -> i32 {
    (text.chars().count() as f64 * f64::from(font_px) / 1.24 * 0.6).ceil() as i32
}

/// The legend as one centred row of entries in `strip`.
pub(super) fn legend_strip(
    strip: &DrawingArea<SVGBackend<'_>, Shift>,
    entries: &[(String, Mark)],
) -> Result<(), String> {
    const SAMPLE: i32 = 26;
    const GAP: i32 = 28;
    let widths: Vec<i32> = entries.iter().map(|(n, _)| SAMPLE + 6 + text_px(n, TICK_PX + 1)).collect();
    let total = widths.iter().sum::<i32>() + GAP * (entries.len() as i32 - 1).max(0);
    let (w, h) = strip.dim_in_pixel();
    let mut x = ((w as i32 - total) / 2).max(4);
    let y = h as i32 / 2;
    let font = (FONT, TICK_PX + 1).into_font().color(&BLACK).pos(Pos::new(HPos::Left, VPos::Center));
    for ((name, mark), ew) in entries.iter().zip(widths) {
        match *mark {
            Mark::Line(s) => strip.draw(&PathElement::new(vec![(x, y), (x + SAMPLE, y)], s.stroke_width(3))),
            Mark::Dashed(s) => strip
                .draw(&PathElement::new(vec![(x, y), (x + 10, y)], s))
                .and_then(|()| strip.draw(&PathElement::new(vec![(x + 16, y), (x + SAMPLE, y)], s))),
            Mark::Patch(s) => strip.draw(&Rectangle::new([(x, y - 7), (x + SAMPLE, y + 7)], s.filled())),
        }
        .map_err(draw_err)?;
        strip.draw(&Text::new(name.as_str(), (x + SAMPLE + 6, y), font.clone())).map_err(draw_err)?;
        x += ew + GAP;
    }
    Ok(())
}

/// Draw the segments of one line.
pub(super) fn draw_line<'a, 'b: 'a>(
    chart: &mut Chart<'a, 'b>,
    segs: &[Vec<(f64, f64)>],
    style: ShapeStyle,
) -> Result<(), String> {
    for seg in segs {
        chart.draw_series(LineSeries::new(seg.iter().copied(), style)).map_err(draw_err)?;
    }
    Ok(())
}

/// A dashed vertical line at `x` over the whole y range with a label at its foot, e.g. the
/// end of the training part.
pub(super) fn boundary<'a, 'b: 'a>(
    chart: &mut Chart<'a, 'b>,
    root: &DrawingArea<SVGBackend<'b>, Shift>,
    x: f64,
    label: &str,
    style: ShapeStyle,
) -> Result<(), String> {
    let (xr, yr) = (chart.x_range(), chart.y_range());
    if !x.is_finite() || !xr.contains(&x) {
        return Ok(());
    }
    chart.draw_series(DashedLineSeries::new([(x, yr.start), (x, yr.end)], 8, 5, style)).map_err(draw_err)?;
    let font = (FONT, TICK_PX).into_font().color(&style.color);
    let (px, py) = chart.backend_coord(&(x, yr.start));
    root.draw(&Text::new(label, (px, py - 6), font.pos(Pos::new(HPos::Center, VPos::Bottom)))).map_err(draw_err)
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
