//! Clipping: a channel flat or pinned at its extreme (sensor/ADC range, end stop), found
//! as episodes of visits to a band at the maximum or minimum that dwell long enough or
//! stay flat long enough.

use super::config::QualityConfig;
use super::runs;
use super::scale::Scale;
use super::warning::{level, Ctx, Warning, WarningKind};
use crate::numerics::units::unit_suffix;

pub(super) fn clipping(ctx: &Ctx, name: &str, v: &[f64], s: &Scale, cfg: &QualityConfig) -> Vec<Warning> {
    let mut out = Vec::new();
    if s.span <= 0.0 {
        return out;
    }
    let band = cfg.clip_band * s.span;
    let flat = 3.0 * s.noise;
    let merge = cfg.clip_merge * s.half_period;
    let flat_needed = ((cfg.clip_flat * s.half_period / ctx.dt).ceil() as usize).max(cfg.clip_flat_samples);
    for (ext, side) in [(s.max, "maximum"), (s.min, "minimum")] {
        let visits = runs(v.iter().map(|x| (x - ext).abs() <= band));
        // Merge visits closer than `merge` into episodes.
        let mut episodes: Vec<Vec<(usize, usize)>> = Vec::new();
        for r in visits {
            match episodes.last_mut() {
                Some(e) if e.last().is_some_and(|p| ctx.t[r.0] - ctx.t[p.1] < merge) => e.push(r),
                _ => episodes.push(vec![r]),
            }
        }
        for e in episodes {
            let (first, last) = (e[0].0, e[e.len() - 1].1);
            let dwell: f64 = e.iter().map(|&(a, b)| (b - a + 1) as f64 * ctx.dt).sum();
            let longest_flat = runs(v[first..=last].iter().map(|x| (x - ext).abs() <= flat))
                .iter()
                .map(|(a, b)| b - a + 1)
                .max()
                .unwrap_or(0);
            if dwell >= cfg.clip_dwell * s.half_period || longest_flat >= flat_needed {
                let what = format!(
                    "{name} clipped at {}{} (its {side}) {}, within {:.0} % of the span of it for {:.2} s",
                    level(ext),
                    unit_suffix(name),
                    ctx.when(first, last),
                    100.0 * cfg.clip_band,
                    dwell,
                );
                out.push(ctx.warning(WarningKind::Clipped, name, first, last, what));
            }
        }
    }
    out
}
