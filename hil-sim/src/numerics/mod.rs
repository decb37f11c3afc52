//! Numerical kernels shared by every room: least squares, descriptive statistics,
//! derivatives of sampled signals, the papers' error metrics, the units of well-known
//! channel names.

pub mod derivative;
pub mod lstsq;
pub mod metrics;
pub mod nnls;
pub mod stats;
pub mod units;
