//! Grouped bar charts: one cluster per category, one bar per group within it.

use std::path::Path;

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::canvas::{draw_err, legend, render, tick};
use super::range::{headroom, pad, range_of};
use super::style::{CAPTION_PX, FONT, LABEL_PX, PALETTE, TICK_PX};
use super::{no_finite, nonempty, same_len, PlotError};

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
