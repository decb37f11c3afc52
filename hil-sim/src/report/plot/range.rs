//! Axis ranges: the range of the finite values, padded (constant series get a span from
//! their magnitude).

use std::ops::Range;

/// Range of the finite values, `None` if there are none.
pub(super) fn range_of(v: impl Iterator<Item = f64>) -> Option<Range<f64>> {
    v.filter(|x| x.is_finite()).fold(None, |acc, x| match acc {
        None => Some(x..x),
        Some(r) => Some(r.start.min(x)..r.end.max(x)),
    })
}

/// Widen a range by `frac` of its span on each side; a constant (or overflowing) range
/// gets a span from its magnitude, so constant series plot as a flat line mid-axis.
pub(super) fn pad(r: Range<f64>, frac: f64) -> Range<f64> {
    let span = r.end - r.start;
    if span.is_finite() && span > 1e-12 * r.start.abs().max(r.end.abs()) && span > f64::MIN_POSITIVE {
        let p = span * frac;
        return (r.start - p)..(r.end + p);
    }
    if !span.is_finite() {
        return (f64::MAX / -4.0)..(f64::MAX / 4.0);
    }
    let mid = 0.5 * (r.start + r.end);
    let half = if mid == 0.0 { 1.0 } else { 0.1 * mid.abs() };
    (mid - half)..(mid + half)
}
