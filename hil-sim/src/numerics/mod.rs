//! Numerical kernels shared by every room: least squares, descriptive statistics,
//! derivatives of sampled signals, the papers' error metrics, the units of well-known
//! channel names, grids.

pub mod derivative;
pub mod lstsq;
pub mod metrics;
pub mod nnls;
pub mod number;
pub mod reduce;
pub mod spans;
pub mod stats;
pub mod units;

/// `f(i)` for each of `rows`, or `None` as soon as one is `None`. Sized once: collected into
/// an `Option<Vec>` the values cannot tell their count, and the vector grows by copying
/// itself (a twentieth of the work of `diagnose`, whose refits gather tens of thousands of
/// training rows per run).
pub fn on_rows(rows: &[usize], f: impl Fn(usize) -> Option<f64>) -> Option<Vec<f64>> {
    let mut out = Vec::with_capacity(rows.len());
    for &i in rows {
        out.push(f(i)?);
    }
    Some(out)
}

/// A number for a message: plain when of ordinary size, in e-notation when huge or tiny
/// (so `1e-300` does not print 300 zeros).
pub fn shown(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1e-4..1e9).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// A log-spaced grid of `n` values from `lo` to `hi` (both > 0).
pub fn log_spaced(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n).map(|k| lo * (hi / lo).powf(k as f64 / (n - 1).max(1) as f64)).collect()
}

#[cfg(test)]
mod tests {
    #[test]
    fn values_on_rows_are_all_or_none() {
        let v = [1.0, 2.0, 3.0];
        assert_eq!(super::on_rows(&[2, 0, 2], |i| v.get(i).copied()), Some(vec![3.0, 1.0, 3.0]));
        assert_eq!(super::on_rows(&[0, 3], |i| v.get(i).copied()), None);
        assert_eq!(super::on_rows(&[], |i| v.get(i).copied()), Some(vec![]));
    }
}
