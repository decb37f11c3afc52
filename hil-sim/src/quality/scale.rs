//! A channel's own scales, measured on the recording: span, noise σ and half-period T½
//! (see the module doc of [`quality`](super)); and the nominal sampling interval.

use crate::numerics::stats::{median, min_max};

/// Mean of the intervals within 0.5–1.5× the median interval, s (the recording's own).
pub(super) fn nominal_dt(t: &[f64]) -> f64 {
    crate::io::recording::nominal_interval(t)
}

/// A channel's own scales (see the module doc).
pub(super) struct Scale {
    pub(super) min: f64,
    pub(super) max: f64,
    pub(super) span: f64,
    pub(super) noise: f64,
    /// s
    pub(super) half_period: f64,
}

impl Scale {
    pub(super) fn of(t: &[f64], v: &[f64]) -> Self {
        let (min, max) = min_max(v);
        let span = max - min;
        let d2: Vec<f64> = v.windows(3).map(|w| w[2] - 2.0 * w[1] + w[0]).collect();
        let m = median(&d2);
        let dev: Vec<f64> = d2.iter().map(|d| (d - m).abs()).collect();
        let quantum = v.windows(2).map(|w| (w[1] - w[0]).abs()).filter(|&d| d > 0.0).fold(f64::INFINITY, f64::min);
        let quantum = if quantum.is_finite() { quantum } else { 0.0 };
        let noise = (1.4826 * median(&dev) / 6f64.sqrt()).max(0.5 * quantum);
        // Half-period: crossings of the median with hysteresis.
        let med = median(v);
        let h = 0.05 * span;
        let (mut state, mut crossings) = (0i8, Vec::new());
        for (i, &x) in v.iter().enumerate() {
            let s = if x > med + h {
                1
            } else if x < med - h {
                -1
            } else {
                continue;
            };
            if s != state {
                if state != 0 {
                    crossings.push(t[i]);
                }
                state = s;
            }
        }
        let intervals: Vec<f64> = crossings.windows(2).map(|w| w[1] - w[0]).collect();
        let duration = t.last().copied().unwrap_or(0.0) - t.first().copied().unwrap_or(0.0);
        let half_period = if intervals.len() >= 3 { median(&intervals) } else { duration };
        Self { min, max, span, noise, half_period }
    }
}
