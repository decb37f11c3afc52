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
