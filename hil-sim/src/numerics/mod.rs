//! Numerical kernels shared by every room: least squares, statistics, derivatives of
//! sampled signals, the papers' error metrics.

pub mod derivative;
pub mod lstsq;
pub mod metrics;
pub mod nnls;
