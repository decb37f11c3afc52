//! Spikes: isolated outliers (1–3 samples) far from the 7-sample median, in units of the
//! local step scale and of the span.

use super::config::QualityConfig;
use super::runs;
use super::scale::Scale;
use super::warning::{level, Ctx, Warning, WarningKind};
use crate::numerics::stats::median;
use crate::numerics::units::unit_suffix;

pub(super) fn spikes(ctx: &Ctx, name: &str, v: &[f64], s: &Scale, cfg: &QualityConfig) -> Vec<Warning> {
    let n = v.len();
    if n < 8 || s.span <= 0.0 {
        return Vec::new();
    }
    const K: usize = 3; // 7-sample median
    const W: usize = 32; // local scale window ±32 samples
    let steps: Vec<f64> = (0..n).map(|i| if i == 0 { (v[1] - v[0]).abs() } else { (v[i] - v[i - 1]).abs() }).collect();
    let mut flagged = vec![false; n];
    let mut buf = Vec::with_capacity(2 * W + 1);
    for i in 0..n {
        let med = median(&v[i.saturating_sub(K)..(i + K + 1).min(n)]);
        let r = (v[i] - med).abs();
        if r < cfg.spike_span * s.span || r < cfg.spike_ratio * s.noise {
            continue;
        }
        buf.clear();
        buf.extend_from_slice(&steps[i.saturating_sub(W)..(i + W + 1).min(n)]);
        let local = (1.4826 * median(&buf)).max(s.noise);
        flagged[i] = r >= cfg.spike_ratio * local;
    }
    runs(flagged)
        .into_iter()
        .filter(|(a, b)| b - a < cfg.spike_samples)
        .map(|(a, b)| {
            let peak = (a..=b).max_by(|&i, &j| v[i].abs().total_cmp(&v[j].abs())).unwrap_or(a);
            let around = median(&v[a.saturating_sub(K)..(b + K + 1).min(n)]);
            let what = format!(
                "{name} spike to {}{} at {:.4} s (neighbours near {}, {} sample{})",
                level(v[peak]),
                unit_suffix(name),
                ctx.t[peak],
                level(around),
                b - a + 1,
                if a == b { "" } else { "s" }
            );
            ctx.warning(WarningKind::Spike, name, a, b, what)
        })
        .collect()
}
