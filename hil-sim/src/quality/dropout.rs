//! Dropouts in a channel: a value held bit for bit for more samples than the channel's
//! own repeat rate makes likely (time gaps are found by [`sampling`](super::sampling)).

use super::config::QualityConfig;
use super::warning::{level, Ctx, Warning, WarningKind};
use crate::numerics::units::unit_suffix;

pub(super) fn holds(ctx: &Ctx, name: &str, v: &[f64], cfg: &QualityConfig) -> Vec<Warning> {
    let n = v.len();
    if n < 2 {
        return Vec::new();
    }
    // Chance of a repeat, and the longest run it makes likely among n samples.
    let repeats = v.windows(2).filter(|w| w[0].to_bits() == w[1].to_bits()).count();
    let p = repeats as f64 / (n - 1) as f64;
    let chance = if p <= 0.0 {
        1.0
    } else if p >= 1.0 {
        n as f64
    } else {
        1.0 + (n as f64).ln() / (1.0 / p).ln()
    };
    let needed = (cfg.hold_samples as f64).max(3.0 * chance).ceil() as usize;
    let mut out = Vec::new();
    let mut a = 0;
    while a < n {
        let mut b = a;
        while b + 1 < n && v[b + 1].to_bits() == v[a].to_bits() {
            b += 1;
        }
        if b - a + 1 >= needed {
            let what = format!(
                "{name} holds {}{} for {} samples {} (dropout?)",
                level(v[a]),
                unit_suffix(name),
                b - a + 1,
                ctx.when(a, b)
            );
            out.push(ctx.warning(WarningKind::Dropout, name, a, b, what));
        }
        a = b + 1;
    }
    out
}
