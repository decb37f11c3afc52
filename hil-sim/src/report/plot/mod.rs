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
//!
//! One file per plot kind: [`time_series()`] (lines over time), [`residual()`] (a residual
//! over time with shaded windows), [`hysteresis_loop()`] (output against input) and [`bars()`]
//! (grouped horizontal bars); `canvas` holds the shared picture, axes, the legend strip under the chart and tick labels,
//! `range` the axis ranges, `decimate` the reduction of long series, `style` the colours.

use std::path::PathBuf;

use thiserror::Error;

mod bars;
mod canvas;
mod decimate;
mod hysteresis;
mod range;
mod residual;
mod style;
mod time_series;

pub use bars::{bars, bars_coloured};
pub use hysteresis::hysteresis_loop;
pub use residual::{residual, residual_shaded};
pub use style::{colour, Style, PALETTE};
pub use time_series::{time_series, time_series_marked, Series};

/// Picture size in pixels (width, height).
pub const SIZE: (u32, u32) = (1000, 530);
/// Most points per x–y series after pixel de-duplication.
pub const MAX_XY_POINTS: usize = 40_000;

/// Plot area width used for decimation (picture width less the y label area and margins).
const PLOT_W: usize = (SIZE.0 - 110) as usize;
const PLOT_H: usize = (SIZE.1 - 134) as usize;

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
    #[error(transparent)]
    Output(#[from] crate::io::output::OutputError),
    #[error("writing {path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
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

#[cfg(test)]
mod tests;
