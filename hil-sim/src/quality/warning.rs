//! A finding ([`Warning`]) and how it names its place: file lines or MAT samples, times,
//! levels with four significant digits and the channel's unit.

use serde::Serialize;

use crate::io::recording::Recording;

/// What a warning is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum WarningKind {
    /// Flat or pinned at the channel's extreme (sensor/ADC range, end stop).
    Clipped,
    /// The input does not move for a long time.
    Standstill,
    /// A value held (bit-identical) for many samples, or a gap in time.
    Dropout,
    /// An isolated outlier (1–3 samples) far from its neighbours.
    Spike,
    /// Sampling intervals far from the nominal one (but no gap).
    NonUniformSampling,
}

/// One finding.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Warning {
    pub kind: WarningKind,
    /// Column name.
    pub channel: String,
    /// Time of the first and last affected sample, seconds.
    pub start_s: f64,
    pub end_s: f64,
    /// File lines (CSV, header = 1) or sample numbers (MAT, first = 1) of the same.
    pub first_line: u64,
    pub last_line: u64,
    /// One human line: `place: what (when)`.
    pub message: String,
    /// 0-based sample indices of the same (for [`Quality::excluded`](super::Quality::excluded)).
    #[serde(skip)]
    pub first_index: usize,
    #[serde(skip)]
    pub last_index: usize,
}

/// Where findings are placed: the recording, its time column (s) and nominal interval.
pub(super) struct Ctx<'a> {
    pub(super) rec: &'a Recording,
    pub(super) t: &'a [f64],
    /// Nominal sampling interval, s.
    pub(super) dt: f64,
}

impl Ctx<'_> {
    pub(super) fn warning(&self, kind: WarningKind, channel: &str, first: usize, last: usize, what: String) -> Warning {
        let line = |i: usize| self.rec.lines.get(i).unwrap_or(i as u64 + 1);
        let (start_s, end_s) = (self.t[first], self.t[last]);
        Warning {
            kind,
            channel: channel.to_owned(),
            start_s,
            end_s,
            first_line: line(first),
            last_line: line(last),
            message: format!("{}: {what}", self.rec.place(first, last)),
            first_index: first,
            last_index: last,
        }
    }

    /// "for the last 0.50 s (19.50–20.00 s)" and the like.
    pub(super) fn when(&self, first: usize, last: usize) -> String {
        let (a, b) = (self.t[first], self.t[last]);
        let d = b - a + self.dt;
        let lead = if last + 1 == self.t.len() {
            "for the last "
        } else if first == 0 {
            "for the first "
        } else {
            "for "
        };
        format!("{lead}{d:.2} s ({a:.2}–{b:.2} s)")
    }
}

/// `v` with four significant digits.
pub(super) fn level(v: f64) -> String {
    let mag = if v == 0.0 { 0 } else { v.abs().log10().floor() as i32 };
    let decimals = (3 - mag).clamp(0, 12) as usize;
    format!("{v:.decimals$}")
}
