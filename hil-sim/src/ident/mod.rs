//! Identification: fit a model to recordings, compare models across recordings, diagnose
//! what a model misses.

pub mod compare;
pub mod dataset;
pub mod diagnose;
pub mod fit;
pub mod own_runs;
pub mod runs;
