//! The time column: gaps (intervals of 1.5 nominal or more, reported as dropouts) and
//! non-uniform sampling (intervals outside (1 ± tolerance)·nominal).

use super::config::QualityConfig;
use super::runs;
use super::warning::{Ctx, Warning, WarningKind};
use crate::numerics::stats::min_max;

pub(super) fn sampling(ctx: &Ctx, name: &str, cfg: &QualityConfig) -> Vec<Warning> {
    let t = ctx.t;
    let dt = ctx.dt;
    if dt <= 0.0 {
        return Vec::new();
    }
    let gap = 1.5f64.max(1.0 + cfg.dt_tolerance);
    let mut out = Vec::new();
    // Interval i lies between samples i and i + 1.
    let ratio: Vec<f64> = t.windows(2).map(|w| (w[1] - w[0]) / dt).collect();
    for (a, b) in runs(ratio.iter().map(|&r| r >= gap)) {
        for i in a..=b {
            let missing = (ratio[i] - 1.0).round();
            let what = format!(
                "{name}: gap of {:.1} ms between {:.4} s and {:.4} s (about {missing:.0} sample{} missing at {:.0} Hz)",
                1e3 * (t[i + 1] - t[i]),
                t[i],
                t[i + 1],
                if missing == 1.0 { "" } else { "s" },
                1.0 / dt
            );
            out.push(ctx.warning(WarningKind::Dropout, name, i, i + 1, what));
        }
    }
    for (a, b) in runs(ratio.iter().map(|&r| r < gap && (r - 1.0).abs() > cfg.dt_tolerance)) {
        let (lo, hi) = min_max(&ratio[a..=b]);
        let what = format!(
            "{name}: {} sampling interval{} of {:.0}–{:.0} % of the nominal {:.3} ms {}",
            b - a + 1,
            if a == b { "" } else { "s" },
            100.0 * lo,
            100.0 * hi,
            1e3 * dt,
            ctx.when(a, b + 1)
        );
        out.push(ctx.warning(WarningKind::NonUniformSampling, name, a, b + 1, what));
    }
    out
}
