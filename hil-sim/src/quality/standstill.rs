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
    runs(still(ctx.t, v, band, min_s))
        .into_iter()
        .map(|(a, b)| {
            let (lo, hi) = min_max(&v[a..=b]);
            let what = format!(
                "{name} does not move {}: it stays within {} to {}{} ({:.1} % of its span)",
                ctx.when(a, b),
                level(lo),
                level(hi),
                unit_suffix(name),
                100.0 * (hi - lo) / s.span
            );
            ctx.warning(WarningKind::Standstill, name, a, b, what)
        })
        .collect()
}

/// Samples belonging to some window of at least `min_s` in which `v` stays within `band`
/// (two pointers with monotone deques: O(n)).
fn still(t: &[f64], v: &[f64], band: f64, min_s: f64) -> Vec<bool> {
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
        if t[j] - t[left] >= min_s {
            for m in mask.iter_mut().take(j + 1).skip(left.max(marked_to)) {
                *m = true;
            }
            marked_to = j + 1;
        }
    }
    mask
}
