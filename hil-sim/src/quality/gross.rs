//! Gross outliers: single samples absurdly far from their neighbours (a logger writing
//! 1e308, a corrupted field), more than [`GROSS_FACTOR`] times the channel's robust range
//! (1st to 99th percentile) away from the 7-sample median. They would set the channel's
//! span, and through it every other check's thresholds; so they are reported as spikes
//! naming their line, and the other checks see the channel with them replaced by the local
//! median. No sample of ordinary data is that far out, so ordinary data is unchanged.

use super::warning::{level, Ctx, Warning, WarningKind};
use crate::numerics::stats::{median, quantile_sorted};
use crate::numerics::units::unit_suffix;

/// How many robust ranges from the local median a gross outlier lies.
pub const GROSS_FACTOR: f64 = 100.0;

/// The channel with its gross outliers replaced by the local median (`None` when it has
/// none), and a spike warning for each.
pub(super) fn gross(ctx: &Ctx, name: &str, v: &[f64]) -> Option<(Vec<f64>, Vec<Warning>)> {
    const K: usize = 3;
    let n = v.len();
    if n < 8 {
        return None;
    }
    let mut sorted = v.to_vec();
    sorted.sort_by(f64::total_cmp);
    let range = quantile_sorted(&sorted, 0.99)? - quantile_sorted(&sorted, 0.01)?;
    let centre = quantile_sorted(&sorted, 0.5)?;
    // A channel constant but for its outliers: its level sets the scale.
    let range = if range > 0.0 { range } else { centre.abs().max(1.0) };
    let mut cleaned = None::<Vec<f64>>;
    let mut warnings = Vec::new();
    for i in 0..n {
        let med = median(&v[i.saturating_sub(K)..(i + K + 1).min(n)]);
        if v[i].is_finite() && (v[i] - med).abs() <= GROSS_FACTOR * range {
            continue;
        }
        cleaned.get_or_insert_with(|| v.to_vec())[i] = med;
        let what = format!(
            "{name} spike to {}{} at {:.4} s, {GROSS_FACTOR:.0}× beyond the channel's range (neighbours near {}): \
             left out",
            crate::numerics::shown(v[i]),
            unit_suffix(name),
            ctx.t[i],
            level(med),
        );
        warnings.push(ctx.warning(WarningKind::Spike, name, i, i, what));
    }
    cleaned.map(|c| (c, warnings))
}
