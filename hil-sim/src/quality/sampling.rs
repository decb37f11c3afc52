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

/// Stamps drifting off the uniform grid: the running sum of (interval / nominal − 1) over
/// the intervals that are not gaps, i.e. how far a stamp sits from its grid point, in
/// intervals. Rounding of the stamps (the Dyke files' 0.1 ms) stays under half an
/// interval; jitter of the sampling clock walks away. `None` within one interval.
pub(super) fn drift(ctx: &Ctx, name: &str, cfg: &QualityConfig) -> Option<String> {
    let dt = ctx.dt;
    if dt <= 0.0 {
        return None;
    }
    let gap = 1.5f64.max(1.0 + cfg.dt_tolerance);
    let (mut dev, mut worst, mut at) = (0.0f64, 0.0f64, 0usize);
    for (i, w) in ctx.t.windows(2).enumerate() {
        let r = (w[1] - w[0]) / dt;
        if r < gap {
            dev += r - 1.0;
            if dev.abs() > worst {
                (worst, at) = (dev.abs(), i + 1);
            }
        }
    }
    let (lo, hi) = min_max(&ctx.t.windows(2).map(|w| (w[1] - w[0]) / dt).collect::<Vec<_>>());
    (worst > 1.0).then(|| {
        format!(
            "{name}: non-uniform sampling: intervals of {:.0}–{:.0} % of the nominal {:.3} ms, the stamps drift \
             up to {worst:.1} intervals off a uniform grid (at {:.4} s); the models step at the nominal interval",
            100.0 * lo,
            100.0 * hi,
            1e3 * dt,
            ctx.t[at]
        )
    })
}
