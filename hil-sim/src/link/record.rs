//! `board record`: the telemetry stream to a CSV recording (`t,b,i,torque_est,reference,
//! duty,mode,fault`, and `torque` when the board sends the true torque, as the virtual
//! board does), optionally while playing a torque-reference profile (CSV `t,reference`,
//! times from the start of the recording, linear between rows).

use std::path::{Path, PathBuf};
use std::time::Duration;

use model_core::protocol::telemetry::Telemetry;
use model_core::protocol::Command;
use serde::Serialize;

use super::client::Link;
use super::error::LinkError;
use crate::progress::Progress;

/// What was recorded.
#[derive(Clone, Debug, Serialize)]
pub struct Recorded {
    pub samples: usize,
    pub file: PathBuf,
    /// Telemetry frames lost on the line (sequence gaps), frames dropped for a bad CRC.
    pub lost: u64,
    pub crc_errors: u64,
}

/// A board that sends nothing for this long has stopped.
const SILENT: Duration = Duration::from_millis(1000);
/// The profile's reference is sent at most this often (board time), s.
const PROFILE_PERIOD: f64 = 1e-3;
/// Without a profile, a command at least this often (board time), s.
const KEEPALIVE_PERIOD: f64 = 20e-3;

/// A reference profile: rows `t,reference` (header optional), times increasing.
pub fn read_profile(path: &Path) -> Result<Vec<(f64, f64)>, LinkError> {
    let err = |why: String| LinkError::Profile { path: path.to_owned(), why };
    let text = std::fs::read_to_string(path).map_err(|e| err(e.to_string()))?;
    let mut rows: Vec<(f64, f64)> = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        let parsed = match cells.as_slice() {
            [a, b] => a.parse::<f64>().ok().zip(b.parse::<f64>().ok()),
            _ => None,
        };
        match parsed {
            Some((t, r)) if t.is_finite() && r.is_finite() => {
                if rows.last().is_some_and(|l| t <= l.0) {
                    return Err(err(format!("line {}: time {t} does not increase", n + 1)));
                }
                rows.push((t, r));
            }
            None if n == 0 => {}
            _ => return Err(err(format!("line {}: expected `t,reference` (two finite numbers)", n + 1))),
        }
    }
    if rows.is_empty() {
        return Err(err("no rows `t,reference`".into()));
    }
    Ok(rows)
}

/// The profile's value at `t` (held before the first and after the last row).
pub fn profile_at(p: &[(f64, f64)], t: f64) -> f64 {
    let k = p.partition_point(|r| r.0 <= t);
    match (k.checked_sub(1).and_then(|i| p.get(i)), p.get(k)) {
        (Some(a), Some(b)) => a.1 + (b.1 - a.1) * (t - a.0) / (b.0 - a.0),
        (Some(a), None) => a.1,
        (None, Some(b)) => b.1,
        (None, None) => 0.0,
    }
}

/// Record `seconds` of board time at every `decimation`-th control sample into `out`.
pub fn record(
    link: &mut Link,
    seconds: f64,
    out: &Path,
    profile: Option<&[(f64, f64)]>,
    decimation: u16,
    progress: &dyn Progress,
) -> Result<Recorded, LinkError> {
    let before = link.stats;
    link.stream(decimation.max(1))?;
    progress.stage("recording", (seconds * 1e3).round() as u64);
    let mut rows: Vec<(f64, Telemetry)> = Vec::new();
    let (mut t0, mut last_us, mut wraps) = (None::<f64>, 0u32, 0u64);
    let mut next_send = 0.0f64;
    let mut done_ms = 0u64;
    'outer: loop {
        for s in link.telemetry(SILENT, "recording")? {
            if s.t_us < last_us {
                wraps += 1;
            }
            last_us = s.t_us;
            let t = (wraps as f64 * 4_294_967_296.0 + f64::from(s.t_us)) * 1e-6;
            let start = *t0.get_or_insert(t);
            // Half a microsecond of slack: board times are whole microseconds.
            if t - start >= seconds - 0.5e-6 {
                break 'outer;
            }
            rows.push((t, s));
            let ms = ((t - start) * 1e3) as u64;
            progress.advance(ms.saturating_sub(done_ms));
            done_ms = done_ms.max(ms);
            if t - start >= next_send {
                // The profile's reference, or a status request that only keeps the link
                // alive (the board releases the drive after 100 ms without a command).
                if let Some(p) = profile {
                    next_send = t - start + PROFILE_PERIOD;
                    link.send(Command::SetTorque(profile_at(p, t - start) as f32))?;
                } else {
                    next_send = t - start + KEEPALIVE_PERIOD;
                    link.send(Command::GetStatus)?;
                }
            }
        }
    }
    link.stream(0)?;
    write_csv(out, &rows)?;
    Ok(Recorded {
        samples: rows.len(),
        file: out.to_owned(),
        lost: link.stats.telemetry_lost - before.telemetry_lost,
        crc_errors: link.stats.crc_errors - before.crc_errors,
    })
}

fn write_csv(out: &Path, rows: &[(f64, Telemetry)]) -> Result<(), LinkError> {
    use std::fmt::Write as _;
    let with_true = rows.iter().any(|(_, s)| s.torque_true.is_finite());
    let mut text = String::from("t,b,i,torque_est,reference,duty,mode,fault");
    text += if with_true { ",torque\n" } else { "\n" };
    for (t, s) in rows {
        let _ = write!(
            text,
            "{t:.6},{},{},{},{},{},{},{}",
            s.b, s.current, s.torque_est, s.reference, s.duty, s.mode, s.fault
        );
        if with_true {
            let _ = write!(text, ",{}", s.torque_true);
        }
        text.push('\n');
    }
    std::fs::write(out, text).map_err(|source| LinkError::Write { path: out.to_owned(), source })
}
