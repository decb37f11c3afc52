//! Data-quality checks on a recording before it is fitted: clipped channels, long
//! standstill of the input, dropouts (held values, time gaps), isolated spikes, and
//! non-uniform sampling. Each finding is a [`Warning`] naming the file lines (or MAT
//! samples), the times and the level; [`Quality::excluded`] marks the samples a fit
//! should leave out.
//!
//! Thresholds are relative to each channel's own scale, measured on the recording:
//! - *span*: max − min;
//! - *noise* σ: 1.4826·MAD of the second differences / √6 (white noise passes, smooth
//!   motion does not), at least half the smallest non-zero step (the quantum);
//! - *half-period* T½: median time between crossings of the channel's median (with a
//!   hysteresis of ±5 % of the span), i.e. the time scale of the channel's own motion.
//!
//! Which channel gets which check: the input and the output get all of them; the command
//! (often a step or on/off signal, legitimately flat at its extremes and with sharp
//! edges) only the held-value check; the time column the sampling checks.
//!
//! One file per check: `gross` (absurd single values, taken out before the others), `clipped`, `standstill`, `dropout` (held values), `spike`,
//! `sampling` (time gaps and non-uniform intervals); `scale` measures a channel's scales,
//! `config` holds the thresholds and `warning` the finding and how it names its place.

use serde::Serialize;

use crate::io::recording::Channels;
use crate::io::recording::{Recording, RecordingError};

mod clipped;
mod config;
mod dropout;
mod gross;
mod sampling;
mod scale;
mod spike;
mod standstill;
pub mod timing;
mod warning;

pub use config::QualityConfig;
pub use warning::{Warning, WarningKind};

use scale::{nominal_dt, Scale};
use warning::Ctx;

/// Everything the check found.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Quality {
    /// Ordered by start time.
    pub warnings: Vec<Warning>,
    /// Samples in the recording.
    pub samples: usize,
    /// Samples inside some warning's range.
    pub excluded_samples: usize,
    /// Findings about the whole recording that exclude no sample (e.g. the sampling
    /// clock's jitter): to be shown with the warnings.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
    /// Gross outliers (single samples 100× beyond the channel's range): never scored, not even with the flagged samples.
    #[serde(skip)]
    pub unusable: Vec<usize>,
}

impl Quality {
    /// Per sample: true when a warning covers it (excluded from fitting).
    pub fn excluded(&self) -> Vec<bool> {
        let mut mask = vec![false; self.samples];
        for w in &self.warnings {
            let last = w.last_index.min(self.samples.saturating_sub(1));
            for m in mask.iter_mut().take(last + 1).skip(w.first_index) {
                *m = true;
            }
        }
        mask
    }
}

/// Check `rec` with the default thresholds.
pub fn check(rec: &Recording, ch: &Channels) -> Result<Quality, RecordingError> {
    check_with(rec, ch, &QualityConfig::default())
}

/// Check `rec` (time column strictly increasing, else the error).
pub fn check_with(rec: &Recording, ch: &Channels, cfg: &QualityConfig) -> Result<Quality, RecordingError> {
    let t = rec.time(&ch.time)?;
    let x = rec.channel(&ch.input)?;
    let y = rec.channel(&ch.output)?;
    let u = ch.command.as_deref().map(|c| rec.channel(c)).transpose()?;
    let n = t.len();
    let ctx = Ctx { rec, t, dt: nominal_dt(t) };
    let mut found: Vec<Warning> = Vec::new();
    let mut unusable = Vec::new();
    found.extend(sampling::sampling(&ctx, &ch.time, cfg));
    let mut signals: Vec<(&str, &[f64], bool)> = vec![(ch.input.as_str(), x, true), (ch.output.as_str(), y, true)];
    if let (Some(name), Some(u)) = (ch.command.as_deref(), u) {
        if name != ch.input && name != ch.output {
            signals.push((name, u, false));
        }
    }
    for (name, v, full) in signals {
        let cleaned = if full { gross::gross(&ctx, name, v) } else { None };
        let v: &[f64] = match &cleaned {
            Some((c, w)) => {
                unusable.extend(w.iter().map(|w| w.first_index));
                found.extend(w.iter().cloned());
                c
            }
            None => v,
        };
        let s = Scale::of(t, v);
        let mut major: Vec<Warning> = Vec::new();
        if full {
            major.extend(clipped::clipping(&ctx, name, v, &s, cfg));
            if name == ch.input {
                major.extend(standstill::standstill(&ctx, name, v, &s, cfg));
            }
        }
        // A held value or a spike inside (or within T½ of) a clipped or still stretch is
        // part of that stretch: not reported twice.
        let margin = (s.half_period / ctx.dt).ceil() as usize;
        let covered = |w: &Warning| {
            major.iter().any(|m| w.first_index <= m.last_index + margin && m.first_index <= w.last_index + margin)
        };
        let mut minor = dropout::holds(&ctx, name, v, cfg);
        if full {
            minor.extend(spike::spikes(&ctx, name, v, &s, cfg));
        }
        minor.retain(|w| !covered(w));
        found.extend(major);
        found.extend(minor);
    }
    standstill::reclassify(&ctx, &ch.input, x, y, &mut found, cfg);
    found.sort_by(|a, b| a.start_s.total_cmp(&b.start_s).then_with(|| a.channel.cmp(&b.channel)));
    unusable.sort_unstable();
    unusable.dedup();
    let notes = sampling::drift(&ctx, &ch.time, cfg).into_iter().collect();
    let mut q = Quality { warnings: found, samples: n, excluded_samples: 0, notes, unusable };
    q.excluded_samples = q.excluded().iter().filter(|&&e| e).count();
    Ok(q)
}

/// Maximal runs of `true`: (first, last) inclusive.
fn runs(mask: impl IntoIterator<Item = bool>) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = None;
    let mut last = 0;
    for (i, m) in mask.into_iter().enumerate() {
        match (m, start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                out.push((s, i - 1));
                start = None;
            }
            _ => {}
        }
        last = i;
    }
    if let Some(s) = start {
        out.push((s, last));
    }
    out
}

#[cfg(test)]
mod tests;
