//! Data-quality checks on a recording before it is fitted: clipped channels, long
//! standstill of the input, dropouts (held values, time gaps), isolated spikes, and
//! non-uniform sampling. Each finding is a [`Warning`] naming the file lines (or MAT
//! samples), the times and the level; [`Quality::excluded`] marks the samples a fit
//! should leave out.
//!
//! Thresholds are relative to each channel's own scale, measured on the recording:
//! - *span*: max − min;
//! - *noise* σ: 1.4826·MAD of the second differences / √6 (white noise passes, smooth
//!   motion does not), at least half the smallest non-zero step (the quantum);
//! - *half-period* T½: median time between crossings of the channel's median (with a
//!   hysteresis of ±5 % of the span), i.e. the time scale of the channel's own motion.
//!
//! Which channel gets which check: the input and the output get all of them; the command
//! (often a step or on/off signal, legitimately flat at its extremes and with sharp
//! edges) only the held-value check; the time column the sampling checks.

use serde::Serialize;

use crate::recording::{Recording, RecordingError};
use crate::replay::Channels;

/// What a warning is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum WarningKind {
    /// Flat or pinned at the channel's extreme (sensor/ADC range, end stop).
    Clipped,
    /// The input does not move for a long time.
    Standstill,
    /// A value held (bit-identical) for many samples, or a gap in time.
    Dropout,
    /// An isolated outlier (1–3 samples) far from its neighbours.
    Spike,
    /// Sampling intervals far from the nominal one (but no gap).
    NonUniformSampling,
}

/// One finding.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Warning {
    pub kind: WarningKind,
    /// Column name.
    pub channel: String,
    /// Time of the first and last affected sample, seconds.
    pub start_s: f64,
    pub end_s: f64,
    /// File lines (CSV, header = 1) or sample numbers (MAT, first = 1) of the same.
    pub first_line: u64,
    pub last_line: u64,
    /// One human line: `place: what (when)`.
    pub message: String,
    /// 0-based sample indices of the same (for [`Quality::excluded`]).
    #[serde(skip)]
    pub first_index: usize,
    #[serde(skip)]
    pub last_index: usize,
}

/// Everything the check found.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Quality {
    /// Ordered by start time.
    pub warnings: Vec<Warning>,
    /// Samples in the recording.
    pub samples: usize,
    /// Samples inside some warning's range.
    pub excluded_samples: usize,
}

impl Quality {
    /// Per sample: true when a warning covers it (excluded from fitting).
    pub fn excluded(&self) -> Vec<bool> {
        let mut mask = vec![false; self.samples];
        for w in &self.warnings {
            let last = w.last_index.min(self.samples.saturating_sub(1));
            for m in mask.iter_mut().take(last + 1).skip(w.first_index) {
                *m = true;
            }
        }
        mask
    }
}

/// Thresholds; [`Default`] gives the documented values.
#[derive(Clone, Debug, PartialEq)]
pub struct QualityConfig {
    /// Clipping band at each extreme, fraction of the span.
    pub clip_band: f64,
    /// Visits to the band closer than this many T½ form one episode.
    pub clip_merge: f64,
    /// An episode is clipping when the signal spends at least this many T½ in the band
    /// (a sine's peak spends 0.18 T½ within 2 % of the span of its top; the free peaks of
    /// the Dyke recordings up to 0.37 T½, their end-stop episode 2.1 T½),
    pub clip_dwell: f64,
    /// or stays within 3σ of the extreme for at least this many T½ and
    pub clip_flat: f64,
    /// at least this many samples.
    pub clip_flat_samples: usize,
    /// Standstill: the input stays within this fraction of its span
    pub standstill_band: f64,
    /// for at least this long (s) and at least `standstill_half_periods` T½.
    pub standstill_min_s: f64,
    pub standstill_half_periods: f64,
    /// Held value: at least this many bit-identical samples, and at least 3× the longest
    /// run the channel's own repeat rate makes likely by chance.
    pub hold_samples: usize,
    /// Spike: distance from the 7-sample median at least this many local scales
    /// (1.4826·median |Δx| over ±32 samples, at least σ),
    pub spike_ratio: f64,
    /// and at least this fraction of the span,
    pub spike_span: f64,
    /// and at most this many samples in a row.
    pub spike_samples: usize,
    /// Sampling: an interval outside (1 ± this)·nominal is non-uniform; 1.5× or more is
    /// a gap (a missing sample). 0.5: a stamp off by less than half an interval still
    /// names its own grid point (the Dyke files' 0.1 ms rounding is 0.3 of an interval).
    pub dt_tolerance: f64,
}

impl Default for QualityConfig {
    fn default() -> Self {
        Self {
            clip_band: 0.02,
            clip_merge: 1.0,
            clip_dwell: 1.0,
            clip_flat: 0.1,
            clip_flat_samples: 10,
            standstill_band: 0.01,
            standstill_min_s: 0.5,
            standstill_half_periods: 4.0,
            hold_samples: 10,
            spike_ratio: 20.0,
            spike_span: 0.02,
            spike_samples: 3,
            dt_tolerance: 0.5,
        }
    }
}

/// Check `rec` with the default thresholds.
pub fn check(rec: &Recording, ch: &Channels) -> Result<Quality, RecordingError> {
    check_with(rec, ch, &QualityConfig::default())
}

/// Check `rec` (time column strictly increasing, else the error).
pub fn check_with(rec: &Recording, ch: &Channels, cfg: &QualityConfig) -> Result<Quality, RecordingError> {
    let t = rec.time(&ch.time)?;
    let x = rec.channel(&ch.input)?;
    let y = rec.channel(&ch.output)?;
    let u = ch.command.as_deref().map(|c| rec.channel(c)).transpose()?;
    let n = t.len();
    let ctx = Ctx { rec, t, dt: nominal_dt(t) };
    let mut found: Vec<Warning> = Vec::new();
    found.extend(sampling(&ctx, &ch.time, cfg));
    let mut signals: Vec<(&str, &[f64], bool)> = vec![(ch.input.as_str(), x, true), (ch.output.as_str(), y, true)];
    if let (Some(name), Some(u)) = (ch.command.as_deref(), u) {
        if name != ch.input && name != ch.output {
            signals.push((name, u, false));
        }
    }
    for (name, v, full) in signals {
        let s = Scale::of(t, v);
        let mut major: Vec<Warning> = Vec::new();
        if full {
            major.extend(clipping(&ctx, name, v, &s, cfg));
            if name == ch.input {
                major.extend(standstill(&ctx, name, v, &s, cfg));
            }
        }
        // A held value or a spike inside (or within T½ of) a clipped or still stretch is
        // part of that stretch: not reported twice.
        let margin = (s.half_period / ctx.dt).ceil() as usize;
        let covered = |w: &Warning| {
            major.iter().any(|m| w.first_index <= m.last_index + margin && m.first_index <= w.last_index + margin)
        };
        let mut minor = holds(&ctx, name, v, cfg);
        if full {
            minor.extend(spikes(&ctx, name, v, &s, cfg));
        }
        minor.retain(|w| !covered(w));
        found.extend(major);
        found.extend(minor);
    }
    found.sort_by(|a, b| a.start_s.total_cmp(&b.start_s).then_with(|| a.channel.cmp(&b.channel)));
    let mut q = Quality { warnings: found, samples: n, excluded_samples: 0 };
    q.excluded_samples = q.excluded().iter().filter(|&&e| e).count();
    Ok(q)
}

struct Ctx<'a> {
    rec: &'a Recording,
    t: &'a [f64],
    /// Nominal sampling interval, s.
    dt: f64,
}

impl Ctx<'_> {
    fn warning(&self, kind: WarningKind, channel: &str, first: usize, last: usize, what: String) -> Warning {
        let line = |i: usize| self.rec.lines.get(i).copied().unwrap_or(i as u64 + 1);
        let (start_s, end_s) = (self.t[first], self.t[last]);
        Warning {
            kind,
            channel: channel.to_owned(),
            start_s,
            end_s,
            first_line: line(first),
            last_line: line(last),
            message: format!("{}: {what}", self.rec.place(first, last)),
            first_index: first,
            last_index: last,
        }
    }

    /// "for the last 0.50 s (19.50–20.00 s)" and the like.
    fn when(&self, first: usize, last: usize) -> String {
        let (a, b) = (self.t[first], self.t[last]);
        let d = b - a + self.dt;
        let lead = if last + 1 == self.t.len() {
            "for the last "
        } else if first == 0 {
            "for the first "
        } else {
            "for "
        };
        format!("{lead}{d:.2} s ({a:.2}–{b:.2} s)")
    }
}

/// Mean of the intervals within 0.5–1.5× the median interval, s.
fn nominal_dt(t: &[f64]) -> f64 {
    let dts: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let med = median(&dts);
    let ok: Vec<f64> = dts.iter().copied().filter(|d| (0.5 * med..=1.5 * med).contains(d)).collect();
    if ok.is_empty() {
        med
    } else {
        ok.iter().sum::<f64>() / ok.len() as f64
    }
}

fn median(v: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let mut w = v.to_vec();
    let mid = w.len() / 2;
    let (_, m, _) = w.select_nth_unstable_by(mid, f64::total_cmp);
    *m
}

/// A channel's own scales (see the module doc).
struct Scale {
    min: f64,
    max: f64,
    span: f64,
    noise: f64,
    /// s
    half_period: f64,
}

impl Scale {
    fn of(t: &[f64], v: &[f64]) -> Self {
        let min = v.iter().copied().fold(f64::INFINITY, f64::min);
        let max = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
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

fn unit(name: &str) -> &'static str {
    // The contract's clutch channels and the Dyke damper files' (shared/data/dyke/README.md).
    match name {
        "t" | "time" => " s",
        "b" => " T",
        "torque" => " N·m",
        "D" => " cm",
        "F" => " N",
        "V" => " cm/s",
        "Y" => " V",
        _ => "",
    }
}

/// `v` with four significant digits.
fn level(v: f64) -> String {
    let mag = if v == 0.0 { 0 } else { v.abs().log10().floor() as i32 };
    let decimals = (3 - mag).clamp(0, 12) as usize;
    format!("{v:.decimals$}")
}

/// Maximal runs of `true`: (first, last) inclusive.
fn runs(mask: impl IntoIterator<Item = bool>) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = None;
    let mut last = 0;
    for (i, m) in mask.into_iter().enumerate() {
        match (m, start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                out.push((s, i - 1));
                start = None;
            }
            _ => {}
        }
        last = i;
    }
    if let Some(s) = start {
        out.push((s, last));
    }
    out
}

fn clipping(ctx: &Ctx, name: &str, v: &[f64], s: &Scale, cfg: &QualityConfig) -> Vec<Warning> {
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
                    unit(name),
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

fn standstill(ctx: &Ctx, name: &str, v: &[f64], s: &Scale, cfg: &QualityConfig) -> Vec<Warning> {
    if s.span <= 0.0 {
        return Vec::new();
    }
    let band = cfg.standstill_band * s.span;
    let min_s = cfg.standstill_min_s.max(cfg.standstill_half_periods * s.half_period);
    runs(still(ctx.t, v, band, min_s))
        .into_iter()
        .map(|(a, b)| {
            let (lo, hi) = v[a..=b].iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &x| (l.min(x), h.max(x)));
            let what = format!(
                "{name} does not move {}: it stays within {} to {}{} ({:.1} % of its span)",
                ctx.when(a, b),
                level(lo),
                level(hi),
                unit(name),
                100.0 * (hi - lo) / s.span
            );
            ctx.warning(WarningKind::Standstill, name, a, b, what)
        })
        .collect()
}

fn holds(ctx: &Ctx, name: &str, v: &[f64], cfg: &QualityConfig) -> Vec<Warning> {
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
                unit(name),
                b - a + 1,
                ctx.when(a, b)
            );
            out.push(ctx.warning(WarningKind::Dropout, name, a, b, what));
        }
        a = b + 1;
    }
    out
}

fn spikes(ctx: &Ctx, name: &str, v: &[f64], s: &Scale, cfg: &QualityConfig) -> Vec<Warning> {
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
                unit(name),
                ctx.t[peak],
                level(around),
                b - a + 1,
                if a == b { "" } else { "s" }
            );
            ctx.warning(WarningKind::Spike, name, a, b, what)
        })
        .collect()
}

fn sampling(ctx: &Ctx, name: &str, cfg: &QualityConfig) -> Vec<Warning> {
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
        let (lo, hi) = ratio[a..=b].iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &r| (l.min(r), h.max(r)));
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

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::recording::Column;

    const FS: f64 = 1000.0;

    /// Deterministic noise in [-1, 1).
    fn noise(n: usize, seed: u64) -> Vec<f64> {
        let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        (0..n)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                (s >> 11) as f64 / (1u64 << 52) as f64 - 1.0
            })
            .collect()
    }

    /// 10 s at 1 kHz: a multi-sine input `b` (span ≈ 5) and an output `torque` = 2·b + noise.
    fn signals() -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let n = 10_000;
        let t: Vec<f64> = (0..n).map(|i| i as f64 / FS).collect();
        let e = noise(n, 1);
        let b: Vec<f64> = t
            .iter()
            .zip(&e)
            .map(|(t, e)| {
                use std::f64::consts::TAU;
                (TAU * 1.3 * t).sin() + 0.8 * (TAU * 2.9 * t + 1.0).sin() + 0.6 * (TAU * 4.7 * t + 2.0).sin() + 1e-3 * e
            })
            .collect();
        let e = noise(n, 2);
        let y = b.iter().zip(&e).map(|(b, e)| 2.0 * b + 2e-3 * e).collect();
        (t, b, y)
    }

    fn rec(t: Vec<f64>, b: Vec<f64>, y: Vec<f64>) -> Recording {
        let col = |name: &str, values| Column { name: name.into(), values };
        Recording::from_columns(Path::new("syn.mat"), vec![col("t", t), col("b", b), col("torque", y)], vec![])
    }

    fn warnings(r: &Recording) -> Vec<(WarningKind, String, f64, f64)> {
        check(r, &Channels::default())
            .unwrap()
            .warnings
            .into_iter()
            .map(|w| (w.kind, w.channel, w.start_s, w.end_s))
            .collect()
    }

    fn near(a: f64, b: f64) -> bool {
        (a - b).abs() <= 0.05
    }

    #[test]
    fn clean_signals_raise_nothing() {
        let (t, b, y) = signals();
        assert_eq!(warnings(&rec(t, b, y)), vec![]);
    }

    #[test]
    fn flat_top_is_clipped() {
        let (t, b, mut y) = signals();
        let top = y.iter().copied().fold(f64::NEG_INFINITY, f64::max) * 1.02;
        // The output pinned at a sensor limit above its free peaks during 6.0–6.5 s.
        for v in &mut y[6000..=6500] {
            *v = top;
        }
        let w = warnings(&rec(t, b, y));
        assert_eq!(w.len(), 1, "{w:?}");
        assert_eq!((w[0].0, w[0].1.as_str()), (WarningKind::Clipped, "torque"));
        assert!(near(w[0].2, 6.0) && near(w[0].3, 6.5), "{w:?}");
    }

    #[test]
    fn bouncing_at_an_end_stop_is_clipped() {
        let (t, mut b, y) = signals();
        let top = b.iter().copied().fold(f64::NEG_INFINITY, f64::max) + 0.1;
        let e = noise(b.len(), 3);
        // The input held at a stop, bouncing by 1 % of its span, during 3.0–3.4 s.
        for i in 3000..=3400 {
            b[i] = top - 0.05 * e[i].abs() * ((i as f64) * 0.3).sin().abs();
        }
        let w = warnings(&rec(t, b, y));
        assert_eq!(w.len(), 1, "{w:?}");
        assert_eq!((w[0].0, w[0].1.as_str()), (WarningKind::Clipped, "b"));
        assert!(near(w[0].2, 3.0) && near(w[0].3, 3.4), "{w:?}");
    }

    #[test]
    fn input_at_rest_is_a_standstill() {
        let (t, mut b, y) = signals();
        let e = noise(b.len(), 4);
        let rest = b[7000];
        for i in 7000..b.len() {
            b[i] = rest + 1e-3 * e[i];
        }
        let w = warnings(&rec(t, b, y));
        assert_eq!(w.len(), 1, "{w:?}");
        assert_eq!((w[0].0, w[0].1.as_str()), (WarningKind::Standstill, "b"));
        assert!(near(w[0].2, 7.0) && near(w[0].3, 9.999), "{w:?}");
        // Shorter than 0.5 s: no warning.
        let (t, mut b, y) = signals();
        let rest = b[7000];
        for v in &mut b[7000..7300] {
            *v = rest;
        }
        let w = warnings(&rec(t, b, y));
        assert!(w.iter().all(|w| w.0 != WarningKind::Standstill), "{w:?}");
    }

    #[test]
    fn held_value_and_time_gap_are_dropouts() {
        let (t, b, mut y) = signals();
        let held = y[4000];
        for v in &mut y[4000..4040] {
            *v = held;
        }
        let w = warnings(&rec(t.clone(), b.clone(), y));
        assert_eq!(w.len(), 1, "{w:?}");
        assert_eq!((w[0].0, w[0].1.as_str()), (WarningKind::Dropout, "torque"));
        assert!(near(w[0].2, 4.0) && near(w[0].3, 4.039), "{w:?}");
        // A 9-sample hold is within chance for nothing here but below the 10-sample floor.
        let (t2, b2, mut y2) = signals();
        let held = y2[4000];
        for v in &mut y2[4000..4009] {
            *v = held;
        }
        assert_eq!(warnings(&rec(t2, b2, y2)), vec![]);
        // 20 samples missing at 5 s.
        let (t, b, y) = signals();
        let keep = |v: &Vec<f64>| [&v[..5000], &v[5020..]].concat();
        let w = warnings(&rec(keep(&t), keep(&b), keep(&y)));
        assert_eq!(w.len(), 1, "{w:?}");
        assert_eq!((w[0].0, w[0].1.as_str()), (WarningKind::Dropout, "t"));
        assert!(near(w[0].2, 4.999) && near(w[0].3, 5.02), "{w:?}");
    }

    #[test]
    fn isolated_outlier_is_a_spike() {
        let (t, mut b, y) = signals();
        b[2500] += 1.0; // 20 % of the span
        let w = warnings(&rec(t, b, y));
        assert_eq!(w.len(), 1, "{w:?}");
        assert_eq!((w[0].0, w[0].1.as_str()), (WarningKind::Spike, "b"));
        assert!(near(w[0].2, 2.5) && near(w[0].3, 2.5), "{w:?}");
        // A step is not a spike.
        let (t, mut b, y) = signals();
        for v in &mut b[2500..] {
            *v += 1.0;
        }
        let w = warnings(&rec(t, b, y));
        assert!(w.iter().all(|w| w.0 != WarningKind::Spike), "{w:?}");
    }

    #[test]
    fn short_intervals_are_non_uniform_sampling() {
        let (mut t, b, y) = signals();
        for (k, v) in t.iter_mut().enumerate().skip(8000) {
            *v -= if k == 8000 { 0.0007 } else { 0.0 };
        }
        // Interval 7999→8000 is 0.3 ms, 8000→8001 1.7 ms: the second is a gap-sized one.
        let w = warnings(&rec(t, b, y));
        let kinds: Vec<WarningKind> = w.iter().map(|w| w.0).collect();
        assert_eq!(kinds, vec![WarningKind::NonUniformSampling, WarningKind::Dropout], "{w:?}");
        assert!(w.iter().all(|w| near(w.2, 8.0) && w.1 == "t"), "{w:?}");
        // 30 % jitter (timestamp rounding) passes.
        let (mut t, b, y) = signals();
        for v in t.iter_mut().skip(1).step_by(3) {
            *v += 0.0003;
        }
        assert_eq!(warnings(&rec(t, b, y)), vec![]);
    }

    #[test]
    fn excluded_marks_the_warned_samples_and_messages_name_places() {
        let (t, mut b, y) = signals();
        b[2500] += 1.0;
        let q = check(&rec(t, b, y), &Channels::default()).unwrap();
        let ex = q.excluded();
        assert_eq!(ex.len(), 10_000);
        assert_eq!(ex.iter().filter(|&&e| e).count(), 1);
        assert!(ex[2500]);
        assert_eq!(q.excluded_samples, 1);
        assert!(q.warnings[0].message.starts_with("syn.mat: sample 2501: b spike to"), "{}", q.warnings[0].message);
        let json = serde_json::to_value(&q).unwrap();
        assert_eq!(json["warnings"][0]["kind"], "spike");
    }
}
