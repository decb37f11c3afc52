//! Where an error concentrates: in time (windows, seconds), in the operating space (input
//! level, rate, direction, auxiliary channels) and in frequency.
//!
//! Every statistic here works on a per-sample "energy" `e(t)`: the squared residual of the
//! base model when locating the misfit, or the drop in squared residual a finding brings
//! (`r_before² − r_after²`) when saying where a term bites.

use rustfft::num_complex::Complex;
use rustfft::FftPlanner;
use serde::Serialize;

use crate::ident::fit::Dataset;

/// One operating condition where the energy concentrates.
#[derive(Clone, Debug, Serialize)]
pub struct Condition {
    /// What was binned (`input`, `|rate|`, `direction`, an auxiliary channel).
    pub variable: String,
    /// Which part (`top quarter`, `rising`, …).
    pub bin: String,
    /// Share of the energy in that part, against the share of samples (1 = no concentration).
    pub concentration: f64,
    /// Share of the energy in that part.
    pub share: f64,
}

/// The energy per frequency band.
#[derive(Clone, Debug, Serialize)]
pub struct Band {
    pub lo_hz: f64,
    pub hi_hz: f64,
    /// Root-mean-square of the signal within the band.
    pub rms: f64,
}

/// Where the base model's residual concentrates before anything is named.
#[derive(Clone, Debug, Serialize)]
pub struct Locate {
    /// RMS of the base residual over the held-out part, output units.
    pub residual_rms: f64,
    /// Sample-to-sample noise floor of the residual (white-noise estimate), output units.
    pub noise_rms: f64,
    pub windows: Vec<(f64, f64)>,
    pub conditions: Vec<Condition>,
    pub bands: Vec<Band>,
}

/// Where the residual `y − base` of `data` concentrates over `rows` (time, operating
/// conditions: the input's `rate` and the channels `aux`) and over frequency (the held-out
/// part); `residual_rms` is its held-out RMS, as scored.
pub fn residual(
    data: &Dataset,
    base: &[f64],
    rows: &[usize],
    rate: &[f64],
    aux: &[(&str, &[f64])],
    residual_rms: f64,
) -> Locate {
    let n = data.len();
    let dt = data.dt;
    let residual: Vec<f64> = data.output.iter().zip(base).map(|(y, m)| y - m).collect();
    let mut energy: Vec<f64> = residual.iter().map(|r| r * r).collect();
    mask(&mut energy, rows);
    let noise_rms = {
        let d2: Vec<f64> =
            (1..n.saturating_sub(1)).map(|i| residual[i] - 0.5 * (residual[i - 1] + residual[i + 1])).collect();
        (d2.iter().map(|v| v * v).sum::<f64>() / d2.len().max(1) as f64 / 1.5).sqrt()
    };
    let fs = 1.0 / dt;
    let edges = band_edges(fs);
    let held_residual: Vec<f64> = (data.train_end..n).map(|i| residual[i]).collect();
    Locate {
        residual_rms,
        noise_rms,
        windows: windows(&data.time, &energy, dt, 2.0, 5),
        conditions: conditions(&data.input, rate, aux, &energy, rows).into_iter().take(5).collect(),
        bands: spectrum(&held_residual, fs, &edges),
    }
}

/// Zero the energy outside `rows`.
pub fn mask(e: &mut [f64], rows: &[usize]) {
    let mut keep = vec![false; e.len()];
    for &i in rows {
        if let Some(k) = keep.get_mut(i) {
            *k = true;
        }
    }
    for (v, k) in e.iter_mut().zip(keep) {
        if !k {
            *v = 0.0;
        }
    }
}

/// A centred moving average of `v` over `w` samples.
fn moving_mean(v: &[f64], w: usize) -> Vec<f64> {
    let n = v.len();
    let w = w.max(1);
    let mut c = Vec::with_capacity(n + 1);
    c.push(0.0);
    let mut s = 0.0;
    for a in v {
        s += a;
        c.push(s);
    }
    (0..n)
        .map(|i| {
            let a = i.saturating_sub(w / 2);
            let b = (i + w / 2 + 1).min(n);
            (c[b] - c[a]) / (b - a).max(1) as f64
        })
        .collect()
}

/// Time windows `[start, end]` (s) where the energy concentrates: where its moving average
/// (over 1/200 of the recording, 0.02–0.5 s) is in its top decile and above half its 97th
/// percentile, merged across gaps shorter than one averaging window, the strongest first (at
/// most `max`). An energy spread evenly (97th percentile below `factor` × the median) has none.
pub fn windows(t: &[f64], e: &[f64], dt: f64, factor: f64, max: usize) -> Vec<(f64, f64)> {
    let n = e.len().min(t.len());
    if n < 4 {
        return Vec::new();
    }
    let duration = n as f64 * dt;
    let w = ((duration / 200.0).clamp(0.02, 0.5) / dt).round() as usize;
    let s = moving_mean(&e[..n], w);
    let mut sorted: Vec<f64> = s.iter().copied().filter(|v| v.is_finite()).collect();
    sorted.sort_by(f64::total_cmp);
    let q = |f: f64| sorted.get(((sorted.len().max(1) - 1) as f64 * f) as usize).copied().unwrap_or(0.0);
    let (median, q90, peak) = (q(0.5), q(0.9), q(0.97));
    // Not positive, or NaN.
    if peak.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) || peak < factor * median {
        return Vec::new();
    }
    let thr = q90.max(0.5 * peak);
    let mut spans: Vec<(usize, usize, f64)> = Vec::new();
    let mut i = 0;
    while i < n {
        if s[i] > thr {
            let a = i;
            while i < n && s[i] > thr {
                i += 1;
            }
            let energy: f64 = e[a..i].iter().sum();
            match spans.last_mut() {
                Some(last) if a.saturating_sub(last.1) < w => {
                    last.1 = i;
                    last.2 += energy;
                }
                _ => spans.push((a, i, energy)),
            }
        } else {
            i += 1;
        }
    }
    spans.sort_by(|a, b| b.2.total_cmp(&a.2));
    spans.truncate(max);
    spans.sort_by_key(|s| s.0);
    spans.iter().map(|&(a, b, _)| (t[a], t[(b - 1).max(a)])).collect()
}

/// Energy shares per quarter of `v` (by value), as conditions.
fn quarters(name: &str, v: &[f64], e: &[f64], rows: &[usize]) -> Vec<Condition> {
    let mut vals: Vec<f64> = rows.iter().filter_map(|&i| v.get(i).copied()).filter(|v| v.is_finite()).collect();
    if vals.len() < 8 {
        return Vec::new();
    }
    vals.sort_by(f64::total_cmp);
    let q = |f: f64| vals[((vals.len() - 1) as f64 * f) as usize];
    let edges = [f64::NEG_INFINITY, q(0.25), q(0.5), q(0.75), f64::INFINITY];
    let names = ["bottom quarter", "second quarter", "third quarter", "top quarter"];
    let total: f64 = rows.iter().map(|&i| e[i]).sum();
    if total.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return Vec::new();
    }
    (0..4)
        .map(|k| {
            let (lo, hi) = (edges[k], edges[k + 1]);
            let inside: Vec<usize> =
                rows.iter().copied().filter(|&i| v.get(i).is_some_and(|x| *x > lo && *x <= hi)).collect();
            let share = inside.iter().map(|&i| e[i]).sum::<f64>() / total;
            let frac = inside.len() as f64 / rows.len() as f64;
            Condition {
                variable: name.to_owned(),
                bin: names[k].to_owned(),
                concentration: if frac > 0.0 { share / frac } else { 0.0 },
                share,
            }
        })
        .collect()
}

/// Where in the operating space `e` concentrates: input level, |rate|, direction of the
/// input and each auxiliary channel, the strongest concentrations first.
pub fn conditions(input: &[f64], rate: &[f64], aux: &[(&str, &[f64])], e: &[f64], rows: &[usize]) -> Vec<Condition> {
    let mut out = quarters("input", input, e, rows);
    let abs_rate: Vec<f64> = rate.iter().map(|v| v.abs()).collect();
    out.extend(quarters("|rate|", &abs_rate, e, rows));
    let total: f64 = rows.iter().map(|&i| e[i]).sum();
    if total > 0.0 {
        for (bin, up) in [("rising", true), ("falling", false)] {
            let inside: Vec<usize> = rows.iter().copied().filter(|&i| (rate[i] > 0.0) == up).collect();
            let share = inside.iter().map(|&i| e[i]).sum::<f64>() / total;
            let frac = inside.len() as f64 / rows.len().max(1) as f64;
            out.push(Condition {
                variable: "direction".into(),
                bin: bin.into(),
                concentration: if frac > 0.0 { share / frac } else { 0.0 },
                share,
            });
        }
    }
    for (name, v) in aux {
        out.extend(quarters(name, v, e, rows));
    }
    out.sort_by(|a, b| b.concentration.total_cmp(&a.concentration));
    out
}

/// Band edges (Hz): octave-like steps from 0.1 Hz to fs/2.
pub fn band_edges(fs: f64) -> Vec<f64> {
    let mut edges = vec![0.0];
    let steps = [0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1000.0, 2000.0, 5000.0];
    edges.extend(steps.iter().copied().filter(|f| *f < 0.5 * fs));
    edges.push(0.5 * fs);
    edges
}

/// Root-mean-square per frequency band of `v` over `rows`' contiguous span (Welch:
/// Hann-windowed segments of about 2 s, half overlapping).
pub fn spectrum(v: &[f64], fs: f64, edges: &[f64]) -> Vec<Band> {
    let n = v.len();
    let seg = ((2.0 * fs) as usize).next_power_of_two().min(n.next_power_of_two() / 2).max(16);
    let mut planner = FftPlanner::<f64>::new();
    let fft = planner.plan_fft_forward(seg);
    let win: Vec<f64> =
        (0..seg).map(|i| 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / seg as f64).cos()).collect();
    let wpow: f64 = win.iter().map(|w| w * w).sum::<f64>();
    let mut psd = vec![0.0; seg / 2 + 1];
    let mut count = 0usize;
    let mut start = 0;
    let mut buf = vec![Complex::new(0.0, 0.0); seg];
    while start + seg <= n {
        let chunk = &v[start..start + seg];
        let m = chunk.iter().sum::<f64>() / seg as f64;
        for ((b, x), w) in buf.iter_mut().zip(chunk).zip(&win) {
            *b = Complex::new((x - m) * w, 0.0);
        }
        fft.process(&mut buf);
        for (k, p) in psd.iter_mut().enumerate() {
            let scale = if k == 0 || k == seg / 2 { 1.0 } else { 2.0 };
            *p += scale * buf[k].norm_sqr() / (wpow * seg as f64);
        }
        count += 1;
        start += seg / 2;
    }
    let df = fs / seg as f64;
    edges
        .windows(2)
        .map(|w| {
            let (lo, hi) = (w[0], w[1]);
            let power: f64 = psd
                .iter()
                .enumerate()
                .filter(|(k, _)| {
                    let f = *k as f64 * df;
                    f >= lo && (f < hi || (hi >= 0.5 * fs && f <= hi))
                })
                .map(|(_, p)| p)
                .sum::<f64>()
                / count.max(1) as f64;
            Band { lo_hz: lo, hi_hz: hi, rms: power.sqrt() }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_burst_is_found_where_it_is() {
        let dt = 1e-3;
        let t: Vec<f64> = (0..20_000).map(|i| i as f64 * dt).collect();
        let e: Vec<f64> = t.iter().map(|t| if (8.0..9.0).contains(t) { 25.0 } else { 1.0 }).collect();
        let w = windows(&t, &e, dt, 3.0, 5);
        assert_eq!(w.len(), 1, "{w:?}");
        assert!((w[0].0 - 8.0).abs() < 0.3 && (w[0].1 - 9.0).abs() < 0.3, "{w:?}");
        // A flat energy has no window.
        assert!(windows(&t, &vec![1.0; t.len()], dt, 3.0, 5).is_empty());
    }

    #[test]
    fn a_sine_lands_in_its_band_with_its_rms() {
        let fs = 1000.0;
        let v: Vec<f64> =
            (0..20_000).map(|i| 2.0 * (2.0 * std::f64::consts::PI * 30.0 * i as f64 / fs).sin()).collect();
        let bands = spectrum(&v, fs, &band_edges(fs));
        let best = bands.iter().max_by(|a, b| a.rms.total_cmp(&b.rms)).unwrap();
        assert!(best.lo_hz <= 30.0 && best.hi_hz > 30.0, "{best:?}");
        let total: f64 = bands.iter().map(|b| b.rms * b.rms).sum::<f64>().sqrt();
        assert!((total - 2.0 / 2f64.sqrt()).abs() < 0.05, "{total}");
    }

    #[test]
    fn conditions_point_at_the_top_quarter() {
        let x: Vec<f64> = (0..1000).map(|i| i as f64).collect();
        let rate = vec![1.0; 1000];
        let e: Vec<f64> = x.iter().map(|x| if *x >= 750.0 { 1.0 } else { 0.0 }).collect();
        let rows: Vec<usize> = (0..1000).collect();
        let c = conditions(&x, &rate, &[], &e, &rows);
        assert_eq!((c[0].variable.as_str(), c[0].bin.as_str()), ("input", "top quarter"));
        assert!(c[0].concentration > 3.5);
    }
}
