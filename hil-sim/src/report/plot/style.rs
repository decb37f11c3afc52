//! How series are drawn: colour, stroke width in pixels, opacity; the fonts of captions,
//! axis labels and ticks; and the colours that mean one thing in every plot of a report
//! ([`colour`]), so that orange is the model's output wherever it appears.

use plotters::prelude::*;

pub(super) const FONT: &str = "sans-serif";
// plotters' SVG backend writes font-size = size / 1.24: these give about 20, 15 and 13 px.
pub(super) const CAPTION_PX: u32 = 25;
pub(super) const LABEL_PX: u32 = 19;
pub(super) const TICK_PX: u32 = 16;

/// Colour-blind safe palette (Okabe–Ito), used in order for series without a colour.
pub const PALETTE: [(u8, u8, u8); 7] =
    [(0, 114, 178), (213, 94, 0), (0, 158, 115), (204, 121, 167), (230, 159, 0), (86, 180, 233), (90, 90, 90)];

/// One meaning per colour across every plot (Okabe–Ito hues).
pub mod colour {
    /// What was measured, or the plant's true value: dark grey.
    pub const MEASURED: (u8, u8, u8) = (70, 70, 70);
    /// The model's output or estimate: vermillion.
    pub const MODEL: (u8, u8, u8) = (213, 94, 0);
    /// The improved result: the closed loop, the model with a finding's term: bluish green.
    pub const IMPROVED: (u8, u8, u8) = (0, 158, 115);
    /// What the result is compared with: the open-loop baseline, the base model: reddish purple.
    pub const BASELINE: (u8, u8, u8) = (204, 121, 167);
    /// A residual (measured − model): blue.
    pub const RESIDUAL: (u8, u8, u8) = (0, 114, 178);
    /// A reference to follow: black.
    pub const REFERENCE: (u8, u8, u8) = (0, 0, 0);
    /// Samples the quality checks flagged, or a finding's windows (shaded): orange.
    pub const FLAGGED: (u8, u8, u8) = (230, 159, 0);
    /// The boundary between the training and the held-out parts: red.
    pub const BOUNDARY: (u8, u8, u8) = (200, 0, 0);
    /// Scores on the training part: light grey.
    pub const TRAIN: (u8, u8, u8) = (170, 170, 170);
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
    /// A solid line of one of the [`colour`] constants, 2 px, slightly transparent.
    pub const fn of(c: (u8, u8, u8)) -> Self {
        Self { color: Some(c), width: 2, opacity: 0.9 }
    }
    pub const fn width(mut self, width: u32) -> Self {
        self.width = width;
        self
    }
    pub const fn opacity(mut self, opacity: f64) -> Self {
        self.opacity = opacity;
        self
    }
    pub(super) fn shape(&self, index: usize) -> ShapeStyle {
        let (r, g, b) = self.color.unwrap_or(PALETTE[index % PALETTE.len()]);
        let a = if self.opacity.is_finite() { self.opacity.clamp(0.0, 1.0) } else { 1.0 };
        RGBColor(r, g, b).mix(a).stroke_width(self.width.max(1))
    }
}

/// A colour constant as a plotters colour.
pub(super) fn rgb(c: (u8, u8, u8)) -> RGBColor {
    RGBColor(c.0, c.1, c.2)
}
