//! `hil-sim simulate`: a current-driven scenario run against the simulated clutch and
//! recorded as a lab would record it.

use std::path::Path;

use super::{current_driver, run, LoopError, Run, T_START};
use crate::io::recording::{Column, Recording};
use crate::sim::scenario::Scenario;

/// A simulated recording of a current-driven scenario, as `hil-sim simulate` writes it.
pub struct Recorded {
    /// The channels [`RECORD_COLUMNS`] at the recording rate, each to the resolution it is
    /// recorded with (e.g. 10 µs in time, 1 µT in the field).
    pub recording: Recording,
    /// The whole run at the control rate (from the start of calibration).
    pub run: Run,
    /// First sample of `run` after calibration.
    pub first: usize,
}

/// Column names of [`Recorded::recording`].
pub const RECORD_COLUMNS: [&str; 9] = ["t", "b", "torque", "i", "i_ref", "duty", "speed", "temperature", "torque_true"];

/// Run scenario `sc` (a current reference) against the simulated clutch and record it at
/// its `record_hz`, time from the end of calibration.
pub fn record(sc: &Scenario) -> Result<Recorded, LoopError> {
    let (step, cfg) = current_driver(&sc.clutch, sc.control_hz)?;
    let dur = sc.duration_s;
    let reference = |t: f64| sc.reference.at(t, dur);
    let r = run(&sc.clutch, &step, cfg, &reference, T_START + dur, sc.seed, None);
    let every = (sc.control_hz / sc.record_hz).round().max(1.0) as usize;
    let k0 = r.after(T_START);
    let ks: Vec<usize> = (k0..r.t.len()).step_by(every).collect();
    let t: Vec<f64> = r.t.iter().map(|t| t - T_START).collect();
    let signals: [(&[f64], usize); 9] = [
        (&t, 5),
        (&r.b, 6),
        (&r.load_cell, 5),
        (&r.current, 5),
        (&r.i_ref, 5),
        (&r.duty, 5),
        (&r.speed, 3),
        (&r.temperature, 3),
        (&r.torque_true, 5),
    ];
    let columns = RECORD_COLUMNS
        .iter()
        .zip(signals)
        .map(|(name, (v, decimals))| Column {
            name: (*name).to_owned(),
            values: ks.iter().map(|&k| resolution(v.get(k).copied().unwrap_or(f64::NAN), decimals)).collect(),
        })
        .collect();
    let recording = Recording::from_columns(Path::new(&format!("{}.csv", sc.name)), columns, Vec::new());
    check_rows(sc, &recording)?;
    Ok(Recorded { recording, run: r, first: k0 })
}

/// Largest magnitude a recorded value may have (N·m, T, A, °C, rad/s, s): beyond it the
/// simulation diverged.
pub const MAX_RECORDED: f64 = 1e9;

/// A recording worth writing: at least one row, every value finite and within
/// ±[`MAX_RECORDED`].
fn check_rows(sc: &Scenario, rec: &Recording) -> Result<(), LoopError> {
    let name = sc.name.clone();
    if rec.is_empty() {
        return Err(LoopError::EmptyRecording { name, duration_s: sc.duration_s, record_hz: sc.record_hz });
    }
    for c in &rec.columns {
        if let Some((row, value)) = c.values.iter().enumerate().find(|(_, v)| !v.is_finite() || v.abs() > MAX_RECORDED)
        {
            return Err(LoopError::NonFinite { name, column: c.name.clone(), row: row + 1, value: *value });
        }
    }
    Ok(())
}

/// `v` to `decimals` decimal places, as a recorder with that resolution stores it.
fn resolution(v: f64, decimals: usize) -> f64 {
    format!("{v:.decimals$}").parse().unwrap_or(v)
}
