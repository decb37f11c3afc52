//! Output against input (a hysteresis loop): the measured loop as a thin light line, the
//! model's loop drawn over it; points on the same pixel are dropped (lossless at the
//! picture's resolution).

use std::path::Path;

use plotters::prelude::*;

use super::canvas::{chart, draw_line, legend_strip, mesh, render, split_legend, Mark};
use super::decimate::xy_decimate;
use super::range::{pad, range_of};
use super::style::{colour, rgb};
use super::{no_finite, nonempty, same_len, PlotError};

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
    let (xr, yr) = (pad(xr, 0.03), pad(yr, 0.05));
    let meas = xy_decimate(x, measured, &xr, &yr);
    let modl = xy_decimate(x, model, &xr, &yr);
    render(path, |root| {
        let (area, strip) = split_legend(root);
        let mut chart = chart(&area, title, xr.clone(), yr.clone())?;
        mesh(&mut chart, x_label, y_label)?;
        let light = rgb(colour::MEASURED).mix(0.45).stroke_width(1);
        draw_line(&mut chart, &meas, light)?;
        // A dense model loop in 2 px hides the measurement under it.
        let points: usize = modl.iter().map(Vec::len).sum();
        let width = if points > 2_000 { 1 } else { 2 };
        let model = rgb(colour::MODEL).mix(0.85).stroke_width(width);
        draw_line(&mut chart, &modl, model)?;
        legend_strip(&strip, &[("measured".into(), Mark::Line(light)), ("model".into(), Mark::Line(model))])
    })
}
