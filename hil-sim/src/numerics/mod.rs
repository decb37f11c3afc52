//! Numerical helpers shared by the host code: descriptive statistics of sample slices and
//! the units of well-known channel names.

pub mod stats;
pub mod units;
