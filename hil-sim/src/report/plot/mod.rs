//! SVG plots of recordings, model outputs and fit results (plotters, SVG backend only).
//!
//! Every function takes plain slices, writes one SVG file and returns `Result<(), PlotError>`.
//! Non-finite points are skipped (a line is broken there), constant series get a padded
//! axis range, zero-length input is an error ([`PlotError::Empty`]). Text is written as SVG
//! `<text>` elements in the viewer's `sans-serif` font: no font files are read.
//!
//! Long series are decimated before drawing so that files stay small whatever the length:
//! time plots keep, per pixel column, the first, lowest, highest and last point (the M4
//! envelope: peaks and the drawn line survive exactly); x–y plots drop consecutive points
//! that fall on the same pixel and, past [`MAX_XY_POINTS`], keep an even stride.

use std::ops::Range;
use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use thiserror::Error;

/// Picture size in pixels (width, height).
pub const SIZE: (u32, u32) = (1000, 500);
/// Most points per x–y series after pixel de-duplication.
pub const MAX_XY_POINTS: usize = 40_000;

const FONT: &str = "sans-serif";
// plotters' SVG backend writes font-size = size / 1.24: these give about 20, 15 and 13 px.
const CAPTION_PX: u32 = 25;
const LABEL_PX: u32 = 19;
const TICK_PX: u32 = 16;
/// Plot area width used for decimation (picture width less the y label area and margins).
const PLOT_W: usize = (SIZE.0 - 110) as usize;
const PLOT_H: usize = (SIZE.1 - 100) as usize;

/// Colour-blind safe palette (Okabe–Ito), used in order for series without a colour.
pub const PALETTE: [(u8, u8, u8); 7] =
    [(0, 114, 178), (213, 94, 0), (0, 158, 115), (204, 121, 167), (230, 159, 0), (86, 180, 233), (90, 90, 90)];

/// Why a plot was not written.
#[derive(Debug, Error)]
pub enum PlotError {
    #[error("{what}: no data (zero-length input)")]
    Empty { what: String },
    #[error("{what}: {got} values, expected {expected} (one per x value)")]
    LengthMismatch { what: String, got: usize, expected: usize },
    #[error("{what}: no finite values to plot")]
    NoFiniteData { what: String },
    #[error("drawing {path}: {msg}")]
    Draw { path: PathBuf, msg: String },
    #[error("writing {path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
}

/// How one series is drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Style {
    /// RGB colour; `None` takes the next [`PALETTE`] colour.
    pub color: Option<(u8, u8, u8)>,
    /// Stroke width in pixels.
    pub width: u32,
    /// 0 (invisible) ..= 1 (opaque).
    pub opacity: f64,
}

impl Default for Style {
    fn default() -> Self {
        Self { color: None, width: 2, opacity: 0.85 }
    }
}

impl Style {
    /// A solid line of the given colour, 2 px.
    pub const fn rgb(r: u8, g: u8, b: u8) -> Self {
        Self { color: Some((r, g, b)), width: 2, opacity: 1.0 }
    }
    pub const fn width(mut self, width: u32) -> Self {
        self.width = width;
        self
    }
    pub const fn opacity(mut self, opacity: f64) -> Self {
        self.opacity = opacity;
        self
    }
    fn shape(&self, index: usize) -> ShapeStyle {
        let (r, g, b) = self.color.unwrap_or(PALETTE[index % PALETTE.len()]);
        let a = if self.opacity.is_finite() { self.opacity.clamp(0.0, 1.0) } else { 1.0 };
        RGBColor(r, g, b).mix(a).stroke_width(self.width.max(1))
    }
}

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
        let mut chart = chart(root, title, pad(xr, 0.0), headroom(pad(yr, 0.05), series.len()))?;
        mesh(&mut chart, x_label, y_label)?;
        for (i, (s, segs)) in series.iter().zip(&lines).enumerate() {
            draw_line(&mut chart, segs, s.style.shape(i), Some(s.name))?;
        }
        legend(&mut chart)
    })
}

/// Output against input: the measured loop as a thin light line, the model's loop drawn
/// over it. `x`, `measured` and `model` have one value per sample.
pub fn hysteresis_loop(
    path: impl AsRef<Path>,
    title: &str,
    x_label: &str,
    y_label: &str,
    x: &[f64],
    measured: &[f64],
    model: &[f64],
) -> Result<(), PlotError> {
    let path = path.as_ref();
    nonempty("input", x.len())?;
    same_len("measured", measured.len(), x.len())?;
    same_len("model", model.len(), x.len())?;
    let xr = range_of(x.iter().copied()).ok_or_else(|| no_finite("input"))?;
    let yr = range_of(measured.iter().chain(model).copied()).ok_or_else(|| no_finite("outputs"))?;
    let (xr, yr) = (pad(xr, 0.03), headroom(pad(yr, 0.05), 2));
    let meas = xy_decimate(x, measured, &xr, &yr);
    let modl = xy_decimate(x, model, &xr, &yr);
    render(path, |root| {
        let mut chart = chart(root, title, xr.clone(), yr.clone())?;
        mesh(&mut chart, x_label, y_label)?;
        let light = RGBColor(90, 90, 90).mix(0.45).stroke_width(1);
        draw_line(&mut chart, &meas, light, Some("measured"))?;
        // A dense model loop in 2 px hides the measurement under it.
        let points: usize = modl.iter().map(Vec::len).sum();
        let width = if points > 2_000 { 1 } else { 2 };
        draw_line(&mut chart, &modl, RGBColor(213, 94, 0).mix(0.85).stroke_width(width), Some("model"))?;
        legend(&mut chart)
    })
}

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

/// Grouped bar chart: one cluster per category, one bar per group within it (legend by
/// group), e.g. held-out R-RMSE per model and frequency. Each group has one value per
/// category; non-finite values leave their bar out.
pub fn bars<S: AsRef<str>, V: AsRef<[f64]>>(
    path: impl AsRef<Path>,
    title: &str,
    y_label: &str,
    categories: &[String],
    groups: &[(S, V)],
) -> Result<(), PlotError> {
    let path = path.as_ref();
    nonempty("categories", categories.len())?;
    if groups.is_empty() {
        return Err(PlotError::Empty { what: "groups".into() });
    }
    for (name, v) in groups {
        same_len(name.as_ref(), v.as_ref().len(), categories.len())?;
    }
    let vals = groups.iter().flat_map(|(_, v)| v.as_ref().iter().copied());
    let yr = range_of(vals.chain([0.0])).ok_or_else(|| no_finite("bar values"))?;
    let yr = headroom(pad(yr, 0.08), groups.len());
    // Bars grow from 0: keep 0 on the axis edge when all values have one sign.
    let yr = if yr.start < 0.0 && yr.start > -1e-300 { 0.0..yr.end } else { yr };
    let nc = categories.len() as f64;
    let ng = groups.len();
    render(path, |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(title, (FONT, CAPTION_PX))
            .margin(15)
            .x_label_area_size(40)
            .y_label_area_size(80)
            .build_cartesian_2d(0.0..nc, yr.clone())
            .map_err(draw_err)?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .disable_x_axis()
            .y_label_formatter(&|v: &f64| tick(*v, yr.end - yr.start))
            .y_desc(y_label)
            .axis_desc_style((FONT, LABEL_PX))
            .label_style((FONT, TICK_PX))
            .light_line_style(TRANSPARENT)
            .bold_line_style(BLACK.mix(0.12))
            .draw()
            .map_err(draw_err)?;
        let base = if yr.start > 0.0 {
            yr.start
        } else if yr.end < 0.0 {
            yr.end
        } else {
            0.0
        };
        let slot = 0.8 / ng as f64;
        for (g, (name, v)) in groups.iter().enumerate() {
            let fill = {
                let (r, gg, b) = PALETTE[g % PALETTE.len()];
                RGBColor(r, gg, b)
            };
            let rects: Vec<_> = v
                .as_ref()
                .iter()
                .enumerate()
                .filter(|(_, y)| y.is_finite())
                .map(|(c, &y)| {
                    let x0 = c as f64 + 0.1 + g as f64 * slot;
                    Rectangle::new([(x0 + 0.05 * slot, base), (x0 + 0.95 * slot, y)], fill.filled())
                })
                .collect();
            chart
                .draw_series(rects)
                .map_err(draw_err)?
                .label(name.as_ref())
                .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 16, y + 6)], fill.filled()));
        }
        // Category names under their cluster.
        let font = (FONT, LABEL_PX).into_font().color(&BLACK).pos(Pos::new(HPos::Center, VPos::Top));
        for (c, name) in categories.iter().enumerate() {
            let (px, py) = chart.backend_coord(&(c as f64 + 0.5, yr.start));
            root.draw(&Text::new(name.as_str(), (px, py + 8), font.clone())).map_err(draw_err)?;
        }
        // Separators between clusters, and the zero line.
        let sep = BLACK.mix(0.15).stroke_width(1);
        for c in 1..categories.len() {
            let x = c as f64;
            chart.draw_series(LineSeries::new([(x, yr.start), (x, yr.end)], sep)).map_err(draw_err)?;
        }
        chart.draw_series(LineSeries::new([(0.0, base), (nc, base)], BLACK.stroke_width(1))).map_err(draw_err)?;
        legend(&mut chart)
    })
}

type Chart<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

fn render<F>(path: &Path, draw: F) -> Result<(), PlotError>
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
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|source| PlotError::Io { path: dir.into(), source })?;
    }
    std::fs::write(path, svg).map_err(|source| PlotError::Io { path: path.into(), source })
}

fn chart<'a, 'b>(
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

fn mesh<'a, 'b: 'a>(chart: &mut Chart<'a, 'b>, x_label: &str, y_label: &str) -> Result<(), String> {
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

fn legend<'a, 'b: 'a>(chart: &mut Chart<'a, 'b>) -> Result<(), String> {
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
fn draw_line<'a, 'b: 'a>(
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
fn tick(v: f64, span: f64) -> String {
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

fn draw_err<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

fn nonempty(what: &str, len: usize) -> Result<(), PlotError> {
    if len == 0 {
        return Err(PlotError::Empty { what: what.into() });
    }
    Ok(())
}

fn same_len(what: &str, got: usize, expected: usize) -> Result<(), PlotError> {
    if got == 0 {
        return Err(PlotError::Empty { what: what.into() });
    }
    if got != expected {
        return Err(PlotError::LengthMismatch { what: what.into(), got, expected });
    }
    Ok(())
}

fn no_finite(what: &str) -> PlotError {
    PlotError::NoFiniteData { what: what.into() }
}

/// Range of the finite values, `None` if there are none.
fn range_of(v: impl Iterator<Item = f64>) -> Option<Range<f64>> {
    v.filter(|x| x.is_finite()).fold(None, |acc, x| match acc {
        None => Some(x..x),
        Some(r) => Some(r.start.min(x)..r.end.max(x)),
    })
}

/// Widen a range by `frac` of its span on each side; a constant (or overflowing) range
/// gets a span from its magnitude, so constant series plot as a flat line mid-axis.
fn pad(r: Range<f64>, frac: f64) -> Range<f64> {
    let span = r.end - r.start;
    if span.is_finite() && span > 1e-12 * r.start.abs().max(r.end.abs()) && span > f64::MIN_POSITIVE {
        let p = span * frac;
        return (r.start - p)..(r.end + p);
    }
    if !span.is_finite() {
        return (f64::MAX / -4.0)..(f64::MAX / 4.0);
    }
    let mid = 0.5 * (r.start + r.end);
    let half = if mid == 0.0 { 1.0 } else { 0.1 * mid.abs() };
    (mid - half)..(mid + half)
}

/// Extend the top of `r` so that a legend of `entries` lines in the upper right corner
/// sits above the data rather than over it.
fn headroom(r: Range<f64>, entries: usize) -> Range<f64> {
    let legend_px = (22 * entries + 24) as f64;
    let frac = (legend_px / PLOT_H as f64).min(0.5);
    let span = r.end - r.start;
    r.start..(r.end + span * frac / (1.0 - frac))
}

/// Split into runs of finite points and decimate each: when a run has more than four
/// points per pixel column, keep per column (in time order) the first, lowest, highest and
/// last point. Assumes `t` increases (samples out of order only cost some decimation).
fn envelope(t: &[f64], y: &[f64], xr: Range<f64>, cols: usize) -> Vec<Vec<(f64, f64)>> {
    let mut segs = Vec::new();
    let mut cur: Vec<(f64, f64)> = Vec::new();
    for (&tv, &yv) in t.iter().zip(y) {
        if tv.is_finite() && yv.is_finite() {
            cur.push((tv, yv));
        } else if !cur.is_empty() {
            segs.push(std::mem::take(&mut cur));
        }
    }
    if !cur.is_empty() {
        segs.push(cur);
    }
    let span = xr.end - xr.start;
    if !(span > 0.0 && span.is_finite()) {
        return segs;
    }
    let scale = cols as f64 / span;
    segs.into_iter().map(|s| if s.len() > 4 * cols { m4(&s, xr.start, scale) } else { s }).collect()
}

fn m4(s: &[(f64, f64)], x0: f64, scale: f64) -> Vec<(f64, f64)> {
    let col = |x: f64| ((x - x0) * scale).floor() as i64;
    let mut out = Vec::new();
    let mut i = 0;
    while let Some(&first) = s.get(i) {
        let c = col(first.0);
        let mut j = i;
        let (mut lo, mut hi) = (i, i);
        while let Some(p) = s.get(j) {
            if col(p.0) != c {
                break;
            }
            if p.1 < s[lo].1 {
                lo = j;
            }
            if p.1 > s[hi].1 {
                hi = j;
            }
            j += 1;
        }
        let last = j - 1;
        let mut idx = [i, lo, hi, last];
        idx.sort_unstable();
        let mut prev = usize::MAX;
        for k in idx {
            if k != prev {
                out.push(s[k]);
                prev = k;
            }
        }
        i = j;
    }
    out
}

/// Runs of finite points of an x–y curve, without consecutive points on the same pixel
/// (lossless at the picture's resolution); past [`MAX_XY_POINTS`] in all an even stride.
fn xy_decimate(x: &[f64], y: &[f64], xr: &Range<f64>, yr: &Range<f64>) -> Vec<Vec<(f64, f64)>> {
    let sx = PLOT_W as f64 / (xr.end - xr.start);
    let sy = PLOT_H as f64 / (yr.end - yr.start);
    let pix = |p: (f64, f64)| (((p.0 - xr.start) * sx).round() as i64, ((p.1 - yr.start) * sy).round() as i64);
    let mut segs: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut cur: Vec<(f64, f64)> = Vec::new();
    let mut last_pix = None;
    for (&a, &b) in x.iter().zip(y) {
        if !(a.is_finite() && b.is_finite()) {
            if !cur.is_empty() {
                segs.push(std::mem::take(&mut cur));
            }
            last_pix = None;
            continue;
        }
        let p = pix((a, b));
        if last_pix != Some(p) {
            cur.push((a, b));
            last_pix = Some(p);
        }
    }
    if !cur.is_empty() {
        segs.push(cur);
    }
    let total: usize = segs.iter().map(Vec::len).sum();
    if total > MAX_XY_POINTS {
        let stride = total.div_ceil(MAX_XY_POINTS);
        for s in &mut segs {
            let last = s.last().copied();
            let mut kept: Vec<_> = s.iter().copied().step_by(stride).collect();
            if let Some(l) = last.filter(|l| kept.last() != Some(l)) {
                kept.push(l);
            }
            *s = kept;
        }
    }
    segs
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)]
    use super::*;

    fn tmp(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join("hil-sim-plot-tests");
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(name)
    }

    fn read_svg(p: &Path) -> String {
        let s = std::fs::read_to_string(p).unwrap();
        assert!(s.starts_with("<svg"), "{}", &s[..s.len().min(80)]);
        assert!(s.trim_end().ends_with("</svg>"));
        s
    }

    /// The contents of the `<text>` elements.
    fn texts(svg: &str) -> Vec<String> {
        svg.split("<text")
            .skip(1)
            .filter_map(|t| Some(t.split_once('>')?.1.split_once("</text>")?.0.trim().to_owned()))
            .collect()
    }

    fn sine(n: usize, f: f64, dt: f64) -> (Vec<f64>, Vec<f64>) {
        let t: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
        let y = t.iter().map(|t| (2.0 * std::f64::consts::PI * f * t).sin()).collect();
        (t, y)
    }

    #[test]
    fn time_series_writes_svg_with_title_and_legend() {
        let (t, y) = sine(3000, 2.0, 1e-3);
        let m: Vec<f64> = y.iter().map(|v| 0.9 * v).collect();
        let p = tmp("ts.svg");
        time_series(
            &p,
            "Force: measured vs model",
            "time (s)",
            "force (N)",
            &t,
            &[Series::new("measured", &y), Series::new("model", &m).style(Style::rgb(200, 0, 0).width(1))],
        )
        .unwrap();
        let s = read_svg(&p);
        for want in ["Force: measured vs model", "measured", "model", "time (s)", "force (N)"] {
            assert!(s.contains(want), "missing {want}");
        }
    }

    #[test]
    fn long_series_are_decimated_and_keep_peaks() {
        let n = 1_000_000;
        let (t, mut y) = sine(n, 3.0, 1e-5);
        y[654_321] = 25.0; // one-sample spike must survive
        let p = tmp("long.svg");
        time_series(&p, "long", "time (s)", "y", &t, &[Series::new("a", &y), Series::new("b", &y)]).unwrap();
        let s = read_svg(&p);
        assert!(s.len() < 500_000, "{} bytes", s.len());
        let segs = envelope(&t, &y, 0.0..t[n - 1], PLOT_W);
        assert!(segs[0].len() <= 4 * PLOT_W + 4);
        assert!(segs[0].iter().any(|p| p.1 == 25.0));
        // The y axis reaches the spike.
        assert!(texts(&s).iter().any(|t| t == "25"), "axis does not reach the spike: {:?}", texts(&s));
    }

    #[test]
    fn nan_constant_and_empty_inputs() {
        let t: Vec<f64> = (0..500).map(|i| i as f64 * 0.01).collect();
        let mut y = vec![3.0; 500];
        y[10] = f64::NAN;
        y[20] = f64::INFINITY;
        let mut tt = t.clone();
        tt[30] = f64::NAN;
        let p = tmp("nan.svg");
        time_series(&p, "constant with holes", "t (s)", "y", &tt, &[Series::new("c", &y)]).unwrap();
        read_svg(&p);
        let nan = vec![f64::NAN; 500];
        assert!(matches!(
            time_series(&p, "x", "t", "y", &t, &[Series::new("n", &nan)]),
            Err(PlotError::NoFiniteData { .. })
        ));
        assert!(matches!(time_series(&p, "x", "t", "y", &[], &[]), Err(PlotError::Empty { .. })));
        assert!(matches!(time_series(&p, "x", "t", "y", &t, &[]), Err(PlotError::Empty { .. })));
        assert!(matches!(
            time_series(&p, "x", "t", "y", &t, &[Series::new("short", &y[..10])]),
            Err(PlotError::LengthMismatch { .. })
        ));
        assert!(matches!(hysteresis_loop(&p, "x", "a", "b", &[], &[], &[]), Err(PlotError::Empty { .. })));
        assert!(matches!(residual(&p, "x", "r", &[], &[], &[], None), Err(PlotError::Empty { .. })));
        let no: [(&str, Vec<f64>); 0] = [];
        assert!(matches!(bars(&p, "x", "y", &[], &no), Err(PlotError::Empty { .. })));
        assert!(matches!(bars(&p, "x", "y", &["a".to_owned()], &no), Err(PlotError::Empty { .. })));
        // A single point and all-equal time stamps do not panic.
        time_series(&p, "one point", "t", "y", &[1.0], &[Series::new("p", &[2.0])]).unwrap();
        time_series(&p, "same t", "t", "y", &[1.0; 5], &[Series::new("p", &[2.0, 3.0, f64::NAN, 1.0, 0.0])]).unwrap();
    }

    #[test]
    fn hysteresis_loop_writes_both_curves_and_bounds_size() {
        let n = 200_000;
        let (t, xs) = sine(n, 5.0, 1e-4);
        let meas: Vec<f64> = t
            .iter()
            .enumerate()
            .map(|(i, t)| (2.0 * std::f64::consts::PI * 5.0 * t).cos() + 0.05 * ((i * 7919 % 101) as f64 / 101.0))
            .collect();
        let mut model: Vec<f64> = t.iter().map(|t| (2.0 * std::f64::consts::PI * 5.0 * t).cos()).collect();
        model[5] = f64::NAN;
        let p = tmp("loop.svg");
        hysteresis_loop(&p, "Loop: force vs displacement", "displacement (cm)", "force (N)", &xs, &meas, &model)
            .unwrap();
        let s = read_svg(&p);
        for want in ["Loop: force vs displacement", "measured", "model", "displacement (cm)"] {
            assert!(s.contains(want), "missing {want}");
        }
        assert!(s.len() < 2_000_000, "{} bytes", s.len());
        assert!(matches!(
            hysteresis_loop(&p, "x", "a", "b", &xs, &meas[..5], &model),
            Err(PlotError::LengthMismatch { .. })
        ));
    }

    #[test]
    fn residual_with_windows_and_train_marker() {
        let (t, y) = sine(150_000, 1.0, 1e-4);
        let p = tmp("res.svg");
        residual(
            &p,
            "Residual, held-out part shaded",
            "force residual (N)",
            &t,
            &y,
            &[(2.0, 3.0), (10.0, 12.0), (f64::NAN, 1.0)],
            Some(12.75),
        )
        .unwrap();
        let s = read_svg(&p);
        for want in ["Residual, held-out part shaded", "residual", "windows", "end of training", "held-out"] {
            assert!(s.contains(want), "missing {want}");
        }
        assert!(s.len() < 1_000_000);
        // No windows, marker outside the axis: plain residual plot.
        residual(&p, "plain", "r (N)", &t, &y, &[], Some(1e9)).unwrap();
        let s = read_svg(&p);
        assert!(!s.contains("end of training") && !s.contains("windows"));
    }

    #[test]
    fn grouped_bars() {
        let cats: Vec<String> = ["bouc_wen", "spencer", "algebraic"].iter().map(|s| s.to_string()).collect();
        let groups = vec![("1 Hz", vec![0.12, 0.08, 0.2]), ("5 Hz", vec![0.15, f64::NAN, 0.25])];
        let p = tmp("bars.svg");
        bars(&p, "Held-out R-RMSE per model", "R-RMSE (%)", &cats, &groups).unwrap();
        let s = read_svg(&p);
        for want in ["Held-out R-RMSE per model", "1 Hz", "5 Hz", "bouc_wen", "spencer", "algebraic", "R-RMSE (%)"] {
            assert!(s.contains(want), "missing {want}");
        }
        // Negative and constant values.
        bars(&p, "neg", "v", &cats, &[("g", [-1.0, 2.0, 0.5])]).unwrap();
        bars(&p, "const", "v", &cats, &[("g", [0.0, 0.0, 0.0])]).unwrap();
        assert!(matches!(bars(&p, "nan", "v", &cats, &[("g", [f64::NAN; 3])]), Ok(())));
        assert!(matches!(bars(&p, "len", "v", &cats, &[("g", [1.0])]), Err(PlotError::LengthMismatch { .. })));
    }

    #[test]
    fn helpers() {
        assert_eq!(pad(2.0..2.0, 0.05), 1.8..2.2);
        assert_eq!(pad(0.0..0.0, 0.05), -1.0..1.0);
        assert_eq!(range_of([f64::NAN, 1.0, -2.0, f64::INFINITY].into_iter()), Some(-2.0..1.0));
        assert_eq!(range_of([f64::NAN].into_iter()), None);
        assert_eq!(tick(3000.0, 5000.0), "3000");
        assert_eq!(tick(-0.0, 2.0), "0");
        assert_eq!(tick(0.25, 1.0), "0.25");
        assert_eq!(tick(0.2, 1.0), "0.2");
        assert_eq!(tick(12.5, 100.0), "12.5");
        assert_eq!(tick(2e-6, 1e-5), "2.00e-6");
        assert_eq!(tick(1e-17, 1.0), "0");
        let segs = envelope(&[0.0, 1.0, 2.0, 3.0], &[1.0, f64::NAN, 2.0, 3.0], 0.0..3.0, 10);
        assert_eq!(segs, vec![vec![(0.0, 1.0)], vec![(2.0, 2.0), (3.0, 3.0)]]);
    }
}
