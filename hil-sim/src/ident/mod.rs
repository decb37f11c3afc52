//! Identification: what a recording says about the clutch.

pub mod diagnose;
