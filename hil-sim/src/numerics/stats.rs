//! Descriptive statistics of sample slices: mean, population standard deviation (1/n),
//! mean square and RMS, median, rank quantiles and extremes.
//!
//! Sums run over the slice in order, so a caller that replaces its own copy of one of
//! these gets the same bits. An empty slice gives 0 (its length counts as 1), except where
//! a function returns an `Option`.

/// Arithmetic mean Σv / n; 0 for an empty slice.
pub fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// [`mean_std`] of the samples `rows` of `v` (indices past its end are left out), without
/// copying them: the same sums in the same order.
pub fn mean_std_at(rows: &[usize], v: &[f64]) -> (f64, f64) {
    let picked = || rows.iter().filter_map(|&i| v.get(i));
    let n = picked().count().max(1) as f64;
    let m = picked().sum::<f64>() / n;
    (m, (picked().map(|a| (a - m) * (a - m)).sum::<f64>() / n).sqrt())
}

/// Mean m and population standard deviation √(Σ(v − m)² / n); (0, 0) for an empty slice.
pub fn mean_std(v: &[f64]) -> (f64, f64) {
    let n = v.len().max(1) as f64;
    let m = v.iter().sum::<f64>() / n;
    (m, (v.iter().map(|a| (a - m) * (a - m)).sum::<f64>() / n).sqrt())
}

/// Population standard deviation √(Σ(v − m)² / n); 0 for an empty slice.
pub fn std(v: &[f64]) -> f64 {
    mean_std(v).1
}

/// Mean square Σv² / n (e.g. a mean squared error of residuals); 0 for an empty slice.
pub fn mean_square(v: &[f64]) -> f64 {
    v.iter().map(|a| a * a).sum::<f64>() / v.len().max(1) as f64
}

/// Root mean square √(Σv² / n); 0 for an empty slice.
pub fn rms(v: &[f64]) -> f64 {
    mean_square(v).sqrt()
}

/// Median as the element of rank ⌊n/2⌋ in [`f64::total_cmp`] order (the upper of the two
/// middle values for even n, no averaging); 0 for an empty slice. `v` is not reordered.
pub fn median(v: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let mut w = v.to_vec();
    let mid = w.len() / 2;
    let (_, m, _) = w.select_nth_unstable_by(mid, f64::total_cmp);
    *m
}

/// Quantile `q` (0..=1) of an ascending `sorted` slice by rank: the element at
/// ⌊(n − 1)·q⌋, no interpolation; `None` for an empty slice.
pub fn quantile_sorted(sorted: &[f64], q: f64) -> Option<f64> {
    sorted.get(((sorted.len().max(1) - 1) as f64 * q) as usize).copied()
}

/// Smallest and largest value by [`f64::min`] / [`f64::max`] (NaN is skipped);
/// (+∞, −∞) for an empty slice.
pub fn min_max(v: &[f64]) -> (f64, f64) {
    v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| (lo.min(x), hi.max(x)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_cases() {
        let v = [3.0, 1.0, 4.0, 1.0, 5.0];
        assert_eq!(mean(&v), 2.8);
        assert_eq!(mean(&[]), 0.0);
        let (m, s) = mean_std(&[2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0]);
        assert_eq!((m, s), (5.0, 2.0));
        assert_eq!(std(&[2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0]), 2.0);
        assert_eq!(mean_square(&[3.0, 4.0, 0.0, 0.0]), 6.25);
        assert_eq!(rms(&[3.0, 4.0, 0.0, 0.0]), 2.5);
        assert_eq!(median(&v), 3.0);
        assert_eq!(median(&[1.0, 2.0]), 2.0);
        assert_eq!(median(&[]), 0.0);
        assert_eq!(quantile_sorted(&[1.0, 2.0, 3.0, 4.0, 5.0], 0.5), Some(3.0));
        assert_eq!(quantile_sorted(&[1.0, 2.0, 3.0, 4.0], 0.97), Some(3.0));
        assert_eq!(quantile_sorted(&[], 0.5), None);
        assert_eq!(min_max(&[2.0, f64::NAN, -1.0, 7.0]), (-1.0, 7.0));
        assert_eq!(min_max(&[]), (f64::INFINITY, f64::NEG_INFINITY));
    }
}
