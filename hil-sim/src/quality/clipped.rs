//! Clipping: a channel flat or pinned at its extreme (sensor/ADC range, end stop), found
//! as episodes of visits to a band at the maximum or minimum that dwell long enough or
//! stay flat long enough, and whose longest hump is level rather than a free peak's curve.

use super::config::QualityConfig;
use super::runs;
use super::scale::Scale;
use super::warning::{level, Ctx, Warning, WarningKind};
use crate::numerics::lstsq;
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
    for (ext, side, sign) in [(s.max, "maximum", 1.0), (s.min, "minimum", -1.0)] {
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
            let long = dwell >= cfg.clip_dwell * s.half_period || longest_flat >= flat_needed;
            // How deep into the band the hump's parabola reaches, and how far it falls from there.
            let (top, fall) = parabola(ctx.t, v, longest_hump(v, &e, ext, 2.0 * band), sign);
            let level_top = fall <= cfg.clip_curved * (top - (sign * ext - band));
            if long && level_top {
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

/// The visits of the longest hump of an episode's `visits`: consecutive visits belong to one
/// hump when the channel stays within `near` of the extreme `ext` between them (noise
/// taking a peak in and out of the band), and to two when it leaves (two peaks).
fn longest_hump<'e>(v: &[f64], visits: &'e [(usize, usize)], ext: f64, near: f64) -> &'e [(usize, usize)] {
    let (mut best, mut start) = (&visits[..visits.len().min(1)], 0);
    let span = |h: &[(usize, usize)]| h.last().map_or(0, |l| l.1) - h.first().map_or(0, |f| f.0);
    for k in 1..=visits.len() {
        let apart = visits.get(k).is_none_or(|r| {
            let gap = v.get(visits[k - 1].1 + 1..r.0).unwrap_or(&[]);
            gap.iter().any(|x| (x - ext).abs() > near)
        });
        if apart {
            let hump = &visits[start..k];
            if span(hump) > span(best) {
                best = hump;
            }
            start = k;
        }
    }
    best
}

/// The least-squares parabola (in time) through `v` from the first to the last sample of
/// the `visits` (inclusive index ranges; the samples between them too, so that noise taking
/// samples out of the band does not bend the fit), with the extreme on the side `sign` (+1
/// the maximum, −1 the minimum, by which `v` is multiplied): its top within that span, and
/// how far it falls from there to the lower of its two ends; `(+∞, 0)` (flat) when fewer
/// than three samples or their times do not determine it.
fn parabola(t: &[f64], v: &[f64], visits: &[(usize, usize)], sign: f64) -> (f64, f64) {
    let flat = (f64::INFINITY, 0.0);
    let (Some(&(a, _)), Some(&(_, b))) = (visits.first(), visits.last()) else { return flat };
    let (Some(ts), Some(vs)) = (t.get(a..=b), v.get(a..=b)) else { return flat };
    let (Some(&t0), Some(&t1)) = (ts.first(), ts.last()) else { return flat };
    let (mid, half) = (0.5 * (t0 + t1), 0.5 * (t1 - t0));
    if ts.len() < 3 || half <= 0.0 {
        return flat;
    }
    let rows: Vec<[f64; 3]> = ts.iter().map(|&ti| (ti - mid) / half).map(|u| [1.0, u, u * u]).collect();
    let y: Vec<f64> = vs.iter().map(|v| sign * v).collect();
    let Some(c) = lstsq::fit_rows(&rows, &y) else { return flat };
    let p = |u: f64| c[0] + c[1] * u + c[2] * u * u;
    let vertex = if c[2] < 0.0 { -c[1] / (2.0 * c[2]) } else { f64::NAN };
    let top = if vertex.abs() <= 1.0 { p(vertex) } else { p(-1.0).max(p(1.0)) };
    (top, (top - p(-1.0).min(p(1.0))).max(0.0))
}
