//! Decimation of long series so that files stay small whatever the length: the M4
//! envelope for time plots, pixel de-duplication and an even stride for x–y plots.

use std::ops::Range;

use super::{MAX_XY_POINTS, PLOT_H, PLOT_W};

/// Split into runs of finite points and decimate each: when a run has more than four
/// points per pixel column, keep per column (in time order) the first, lowest, highest and
/// last point. Assumes `t` increases (samples out of order only cost some decimation).
pub(super) fn envelope(t: &[f64], y: &[f64], xr: Range<f64>, cols: usize) -> Vec<Vec<(f64, f64)>> {
    let mut segs = Vec::new();
    let mut cur: Vec<(f64, f64)> = Vec::new();
    for (&tv, &yv) in t.iter().zip(y) {
        if tv.is_finite() && yv.is_finite() {
            cur.push((tv, yv));
        } else if !cur.is_empty() {
            segs.push(std::mem::take(&mut cur));
        }
    }
    if !cur.is_empty() {
        segs.push(cur);
    }
    let span = xr.end - xr.start;
    if !(span > 0.0 && span.is_finite()) {
        return segs;
    }
    let scale = cols as f64 / span;
    segs.into_iter().map(|s| if s.len() > 4 * cols { m4(&s, xr.start, scale) } else { s }).collect()
}

fn m4(s: &[(f64, f64)], x0: f64, scale: f64) -> Vec<(f64, f64)> {
    let col = |x: f64| ((x - x0) * scale).floor() as i64;
    let mut out = Vec::new();
    let mut i = 0;
    while let Some(&first) = s.get(i) {
        let c = col(first.0);
        let mut j = i;
        let (mut lo, mut hi) = (i, i);
        while let Some(p) = s.get(j) {
            if col(p.0) != c {
                break;
            }
            if p.1 < s[lo].1 {
                lo = j;
            }
            if p.1 > s[hi].1 {
                hi = j;
            }
            j += 1;
        }
        let last = j - 1;
        let mut idx = [i, lo, hi, last];
        idx.sort_unstable();
        let mut prev = usize::MAX;
        for k in idx {
            if k != prev {
                out.push(s[k]);
                prev = k;
            }
        }
        i = j;
    }
    out
}

/// Runs of finite points of an x–y curve, without consecutive points on the same pixel
/// (lossless at the picture's resolution); past [`MAX_XY_POINTS`] in all an even stride.
pub(super) fn xy_decimate(x: &[f64], y: &[f64], xr: &Range<f64>, yr: &Range<f64>) -> Vec<Vec<(f64, f64)>> {
    let sx = PLOT_W as f64 / (xr.end - xr.start);
    let sy = PLOT_H as f64 / (yr.end - yr.start);
    let pix = |p: (f64, f64)| (((p.0 - xr.start) * sx).round() as i64, ((p.1 - yr.start) * sy).round() as i64);
    let mut segs: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut cur: Vec<(f64, f64)> = Vec::new();
    let mut last_pix = None;
    for (&a, &b) in x.iter().zip(y) {
        if !(a.is_finite() && b.is_finite()) {
            if !cur.is_empty() {
                segs.push(std::mem::take(&mut cur));
            }
            last_pix = None;
            continue;
        }
        let p = pix((a, b));
        if last_pix != Some(p) {
            cur.push((a, b));
            last_pix = Some(p);
        }
    }
    if !cur.is_empty() {
        segs.push(cur);
    }
    let total: usize = segs.iter().map(Vec::len).sum();
    if total > MAX_XY_POINTS {
        let stride = total.div_ceil(MAX_XY_POINTS);
        for s in &mut segs {
            let last = s.last().copied();
            let mut kept: Vec<_> = s.iter().copied().step_by(stride).collect();
            if let Some(l) = last.filter(|l| kept.last() != Some(l)) {
                kept.push(l);
            }
            *s = kept;
        }
    }
    segs
}
