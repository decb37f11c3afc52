//! Grouped bar charts, drawn horizontally: one row per category (its name on the left,
//! where long names cannot run into each other), one bar per group within the row. The
//! picture grows with the number of rows.

use std::path::Path;

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::canvas::{draw_err, legend_strip, render_sized, split_legend, text_px, tick, Mark, LEGEND_H};
use super::range::{pad, range_of};
use super::style::{CAPTION_PX, FONT, LABEL_PX, PALETTE, TICK_PX};
use super::{no_finite, nonempty, same_len, PlotError, SIZE};

/// One group of bars: its legend name, one value per category, and its colour (`None`:
/// the palette's next).
pub type BarGroup<'a> = (&'a str, &'a [f64], Option<(u8, u8, u8)>);

/// Height of one bar, pixels.
const BAR_PX: u32 = 11;

/// Grouped bar chart: one row per category, one bar per group within it (legend by group),
/// e.g. held-out R-RMSE per model, training and held-out. Each group has one value per
/// category and its colour (`None`: the palette's next); non-finite values leave their bar
/// out. `x_label` names the value with its unit.
pub fn bars<S: AsRef<str>, V: AsRef<[f64]>>(
    path: impl AsRef<Path>,
    title: &str,
    x_label: &str,
    categories: &[String],
    groups: &[(S, V)],
) -> Result<(), PlotError> {
    let coloured: Vec<BarGroup<'_>> = groups.iter().map(|(n, v)| (n.as_ref(), v.as_ref(), None)).collect();
    bars_coloured(path, title, x_label, categories, &coloured)
}

/// [`bars`] with a colour per group (e.g. the [`super::style::colour`] constants).
pub fn bars_coloured(
    path: impl AsRef<Path>,
    title: &str,
    x_label: &str,
    categories: &[String],
    groups: &[BarGroup<'_>],
) -> Result<(), PlotError> {
    let path = path.as_ref();
    nonempty("categories", categories.len())?;
    if groups.is_empty() {
        return Err(PlotError::Empty { what: "groups".into() });
    }
    for (name, v, _) in groups {
        same_len(name, v.len(), categories.len())?;
    }
    let vals = groups.iter().flat_map(|(_, v, _)| v.iter().copied());
    let xr = range_of(vals.chain([0.0])).ok_or_else(|| no_finite("bar values"))?;
    let xr = pad(xr, 0.04);
    // Bars grow from 0: keep 0 on the axis edge when all values have one sign.
    let xr = if xr.start < 0.0 && xr.start > -1e-300 { 0.0..xr.end } else { xr };
    let nc = categories.len();
    let ng = groups.len();
    let row_px = (BAR_PX * ng as u32 + 10).max(24);
    let label_px = categories.iter().map(|c| text_px(c, LABEL_PX)).max().unwrap_or(0).clamp(40, 400) as u32 + 24;
    let height = 70 + 50 + LEGEND_H + row_px * nc as u32;
    let base = if xr.start > 0.0 {
        xr.start
    } else if xr.end < 0.0 {
        xr.end
    } else {
        0.0
    };
    render_sized(path, (SIZE.0, height), |root| {
        let (area, strip) = split_legend(root);
        let mut chart = ChartBuilder::on(&area)
            .caption(title, (FONT, CAPTION_PX))
            .margin(15)
            .x_label_area_size(50)
            .y_label_area_size(label_px)
            .build_cartesian_2d(xr.clone(), 0.0..nc as f64)
            .map_err(draw_err)?;
        chart
            .configure_mesh()
            .disable_y_mesh()
            .disable_y_axis()
            .x_label_formatter(&|v: &f64| tick(*v, xr.end - xr.start))
            .x_desc(x_label)
            .axis_desc_style((FONT, LABEL_PX))
            .label_style((FONT, TICK_PX))
            .light_line_style(TRANSPARENT)
            .bold_line_style(BLACK.mix(0.12))
            .draw()
            .map_err(draw_err)?;
        // Row c (from the top) spans y = nc - c - 1 .. nc - c.
        let slot = 0.8 / ng as f64;
        let mut entries = Vec::new();
        for (g, (name, v, colour)) in groups.iter().enumerate() {
            let (r, gg, b) = colour.unwrap_or(PALETTE[g % PALETTE.len()]);
            let fill = RGBColor(r, gg, b).filled();
            let rects: Vec<_> = v
                .iter()
                .enumerate()
                .filter(|(_, x)| x.is_finite())
                .map(|(c, &x)| {
                    let y1 = (nc - c) as f64 - 0.1 - g as f64 * slot;
                    Rectangle::new([(base, y1 - 0.92 * slot), (x, y1)], fill)
                })
                .collect();
            chart.draw_series(rects).map_err(draw_err)?;
            entries.push(((*name).to_owned(), Mark::Patch(fill)));
        }
        // Category names left of their row.
        let font = (FONT, LABEL_PX).into_font().color(&BLACK).pos(Pos::new(HPos::Right, VPos::Center));
        for (c, name) in categories.iter().enumerate() {
            let (px, py) = chart.backend_coord(&(xr.start, (nc - c) as f64 - 0.5));
            area.draw(&Text::new(name.as_str(), (px - 8, py), font.clone())).map_err(draw_err)?;
        }
        // Separators between rows, and the zero line.
        let sep = BLACK.mix(0.1).stroke_width(1);
        for c in 1..nc {
            let y = c as f64;
            chart.draw_series(LineSeries::new([(xr.start, y), (xr.end, y)], sep)).map_err(draw_err)?;
        }
        chart
            .draw_series(LineSeries::new([(base, 0.0), (base, nc as f64)], BLACK.stroke_width(1)))
            .map_err(draw_err)?;
        legend_strip(&strip, &entries)
    })
}
