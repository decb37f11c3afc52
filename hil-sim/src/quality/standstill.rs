//! Standstill: the input stays within a small band of its span for a long time (O(n)
//! sliding window with monotone deques).

use super::config::QualityConfig;
use super::runs;
use super::scale::Scale;
use super::warning::{level, Ctx, Warning, WarningKind};
use crate::numerics::stats::min_max;
use crate::numerics::units::unit_suffix;

pub(super) fn standstill(ctx: &Ctx, name: &str, v: &[f64], s: &Scale, cfg: &QualityConfig) -> Vec<Warning> {
    if s.span <= 0.0 {
        return Vec::new();
    }
    let band = cfg.standstill_band * s.span;
    let min_s = cfg.standstill_min_s.max(cfg.standstill_half_periods * s.half_period);
    runs(still(ctx.dt, v, band, min_s))
        .into_iter()
        .map(|(a, b)| {
            let (lo, hi) = min_max(&v[a..=b]);
            let what = format!("{name} does not move {}: {}", ctx.when(a, b), stays_within(name, lo, hi, s.span));
            ctx.warning(WarningKind::Standstill, name, a, b, what)
        })
        .collect()
}

/// "it stays within LO to HI UNIT (P % of its span)": the band a channel `name` keeps to.
fn stays_within(name: &str, lo: f64, hi: f64, span: f64) -> String {
    format!(
        "it stays within {} to {}{} ({:.1} % of its span)",
        level(lo),
        level(hi),
        unit_suffix(name),
        100.0 * (hi - lo) / span
    )
}

/// Samples belonging to some window of at least `min_s` of recorded time (samples × the
/// nominal interval `dt`: a gap in the stamps is missing data, not a rest) in which `v`
/// stays within `band` (two pointers with monotone deques: O(n)).
fn still(dt: f64, v: &[f64], band: f64, min_s: f64) -> Vec<bool> {
    use std::collections::VecDeque;
    let n = v.len();
    let mut mask = vec![false; n];
    let (mut hi, mut lo): (VecDeque<usize>, VecDeque<usize>) = (VecDeque::new(), VecDeque::new());
    let mut left = 0;
    let mut marked_to = 0; // mask is set on [.., marked_to)
    for j in 0..n {
        while hi.back().is_some_and(|&k| v[k] <= v[j]) {
            hi.pop_back();
        }
        hi.push_back(j);
        while lo.back().is_some_and(|&k| v[k] >= v[j]) {
            lo.pop_back();
        }
        lo.push_back(j);
        while let (Some(&h), Some(&l)) = (hi.front(), lo.front()) {
            if v[h] - v[l] <= band {
                break;
            }
            left += 1;
            if h < left {
                hi.pop_front();
            }
            if l < left {
                lo.pop_front();
            }
        }
        if (j - left) as f64 * dt >= min_s {
            for m in mask.iter_mut().take(j + 1).skip(left.max(marked_to)) {
                *m = true;
            }
            marked_to = j + 1;
        }
    }
    mask
}

/// The input at rest, wherever it is (at the start, between tests, at the end), is a
/// standstill — not a clipped minimum or a dropout. An input clipping or hold episode is one
/// when the output stays quiet through it (within `standstill_output_band` of its span: a real
/// dropout or a clipped sensor leaves the device, and so the output, moving; an end stop
/// pushes back). Such warnings become standstill warnings, and a hold
/// or a flat extreme of another channel inside an input standstill is dropped.
pub(super) fn reclassify(ctx: &Ctx, input: &str, x: &[f64], y: &[f64], found: &mut Vec<Warning>, cfg: &QualityConfig) {
    let n = x.len();
    let (ylo, yhi) = min_max(y);
    let y_span = yhi - ylo;
    let (xlo, xhi) = min_max(x);
    let x_span = (xhi - xlo).max(f64::MIN_POSITIVE);
    let quiet = |a: usize, b: usize| {
        let (lo, hi) = min_max(y.get(a..=b).unwrap_or(&[]));
        y_span <= 0.0 || hi - lo <= cfg.standstill_output_band * y_span
    };
    let mut rest: Vec<Warning> = Vec::new();
    found.retain(|w| {
        let candidate = w.channel == input && matches!(w.kind, WarningKind::Clipped | WarningKind::Dropout);
        let (a, b) = (w.first_index, w.last_index.min(n.saturating_sub(1)));
        if !candidate || !quiet(a, b) {
            return true;
        }
        let (lo, hi) = min_max(x.get(a..=b).unwrap_or(&[]));
        let place = match (a == 0, b + 1 >= n) {
            (true, _) => "before the test starts",
            (_, true) => "after the test ends",
            _ => "between tests",
        };
        let what = format!(
            "{input} at rest {} ({place}, a standstill): {}",
            ctx.when(a, b),
            stays_within(input, lo, hi, x_span)
        );
        rest.push(ctx.warning(WarningKind::Standstill, input, a, b, what));
        false
    });
    // Holds and flat extremes of the other channels inside a standstill are the rest too.
    let stills: Vec<(usize, usize)> = found
        .iter()
        .chain(&rest)
        .filter(|w| w.channel == input && w.kind == WarningKind::Standstill)
        .map(|w| (w.first_index, w.last_index))
        .collect();
    found.retain(|w| {
        let at_rest = matches!(w.kind, WarningKind::Dropout | WarningKind::Clipped) && w.channel != input;
        !at_rest || !stills.iter().any(|&(a, b)| a <= w.first_index && w.last_index <= b)
    });
    found.extend(rest);
}
