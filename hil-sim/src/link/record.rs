//! `board record`: the telemetry stream to a CSV recording (`t,b,i,torque_est,reference,
//! duty,mode,fault`, and `torque` when the board sends the true torque, as the virtual
//! board does), optionally while playing a torque-reference profile (CSV `t,reference`,
//! times from the start of the recording, linear between rows).
//!
//! A recording is honest or it is not written as whole: when the board leaves closed loop
//! while this host drives it, refuses a set-point, stops streaming, resets, or its clock
//! stops, the samples recorded so far are kept in a partial file beside the output
//! (`NAME.partial.csv`, with `NAME.partial.txt` saying why and where it ended) and the
//! recording ends with an error. Everything is checked before the clutch is driven: the
//! output (through `io::output`), the length, the profile against the running page's limit.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use model_core::control::Mode;
use model_core::protocol::telemetry::Telemetry;
use model_core::protocol::{mode_code, quantise_reference, Command};
use serde::Serialize;

use super::client::{fault_name, mode_name, Limits, Link};
use super::error::LinkError;
use crate::io::output;
use crate::progress::Progress;

/// What was recorded.
#[derive(Clone, Debug, Serialize)]
pub struct Recorded {
    pub samples: usize,
    pub file: PathBuf,
    /// Telemetry frames lost on the line (sequence gaps), frames dropped for a bad CRC,
    /// frames that came twice or out of order (not recorded).
    pub lost: u64,
    pub crc_errors: u64,
    pub out_of_order: u64,
}

/// A board that streams nothing for this long has stopped.
const SILENT: Duration = Duration::from_millis(1000);
/// The profile's reference is sent at most this often (board time), s.
const PROFILE_PERIOD: f64 = 1e-3;
/// While this host drives the board, a heartbeat at least this often (board time), s (the
/// board releases the drive after 100 ms without a command of its session).
const KEEPALIVE_PERIOD: f64 = 20e-3;
/// While this host drives, the board's clock is read again this often (board time), s.
const RESYNC_PERIOD: f64 = 1.0;
/// Shortest and longest recording, s: a few hundred samples at the least, so that `fit`
/// has something to fit; a day at the most.
pub const SECONDS: (f64, f64) = (0.1, 86_400.0);
/// Largest decimation (every n-th control sample).
pub const DECIMATE_MAX: u16 = 1000;

/// A reference profile: rows `t,reference` (header optional), times increasing. The file
/// is noted as an input: no output of this run may overwrite it.
pub fn read_profile(path: &Path) -> Result<Vec<(f64, f64)>, LinkError> {
    let err = |why: String| LinkError::Profile { path: path.to_owned(), why };
    let text = std::fs::read_to_string(path).map_err(|e| err(e.to_string()))?;
    output::note_input(path);
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

/// Every row of `profile` within the board's reference limit (refused naming the first
/// row beyond it and the limit).
pub fn check_profile(path: &Path, profile: &[(f64, f64)], limits: &Limits) -> Result<(), LinkError> {
    let max = f64::from(limits.reference_max);
    match profile.iter().position(|(_, r)| r.is_nan() || r.abs() > max) {
        None => Ok(()),
        Some(k) => Err(LinkError::Profile {
            path: path.to_owned(),
            why: format!(
                "row {} (t = {} s): reference {} beyond the running page's limit of ±{max} (its torque_max)",
                k + 1,
                profile[k].0,
                profile[k].1
            ),
        }),
    }
}

/// The checks before anything is driven: the length and decimation in range, the output
/// writable (not an input, not a symbolic link, its folder there or made now).
pub fn check_request(seconds: f64, decimation: u16, out: &Path) -> Result<(), LinkError> {
    let bad = |why: String| LinkError::Request { why };
    if !(SECONDS.0..=SECONDS.1).contains(&seconds) {
        return Err(bad(format!("--seconds {seconds}: expected {} to {} s", SECONDS.0, SECONDS.1)));
    }
    if decimation == 0 || decimation > DECIMATE_MAX {
        return Err(bad(format!("--decimate {decimation}: expected 1 to {DECIMATE_MAX}")));
    }
    let w = |source: output::OutputError| LinkError::Output { source };
    for p in [out.to_path_buf(), partial(out, "csv"), partial(out, "txt")] {
        output::check(&p).map_err(w)?;
    }
    let dir = out.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    output::create_dir(dir).map_err(w)?;
    // The folder takes a file (permissions, a read-only mount): found out now, not after
    // the clutch was driven.
    let probe = dir.join(format!(".hil-sim-record-{}.probe", std::process::id()));
    std::fs::write(&probe, b"").map_err(|source| LinkError::Write { path: dir.to_path_buf(), source })?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// `out` with `.partial.EXT` for its extension.
pub fn partial(out: &Path, ext: &str) -> PathBuf {
    let stem = out.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    out.with_file_name(format!("{stem}.partial.{ext}"))
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

/// How a recording is run.
pub struct Plan<'a> {
    pub seconds: f64,
    pub out: &'a Path,
    pub profile: Option<&'a [(f64, f64)]>,
    pub decimation: u16,
    /// This host drives the board (it enabled the bridge, or plays a profile): the session
    /// is kept alive and leaving closed loop ends the recording.
    pub driving: bool,
}

/// Why a recording ended before its time.
#[derive(Debug)]
enum Cut {
    Link(LinkError),
    LeftLoop { t: f64, mode: u8, fault: u8 },
    Refused(String),
    ClockStopped { t: f64 },
}

impl Cut {
    fn describe(&self) -> String {
        match self {
            Self::Link(e) => e.to_string(),
            Self::LeftLoop { t, mode, fault } => format!(
                "the board left closed loop at t = {t:.4} s (mode {}, fault {})",
                mode_name(*mode),
                fault_name(*fault)
            ),
            Self::Refused(why) => format!("the board refused a set-point: {why}"),
            Self::ClockStopped { t } => {
                format!("the board's telemetry clock stopped at t = {t:.4} s (frames kept coming, time did not move)")
            }
        }
    }
}

/// Record `plan.seconds` of board time at every `decimation`-th control sample into
/// `plan.out`; a recording cut short is kept as a partial file and returned as the error.
pub fn record(link: &mut Link, plan: &Plan<'_>, progress: &dyn Progress) -> Result<Recorded, LinkError> {
    let before = link.stats;
    link.stream(plan.decimation)?;
    progress.stage("recording", (plan.seconds * 1e3).round() as u64);
    let mut rows: Vec<(f64, Telemetry)> = Vec::new();
    let cut = stream_rows(link, plan, progress, &mut rows);
    let _ = link.stream(0);
    let stats = |file: PathBuf| Recorded {
        samples: rows.len(),
        file,
        lost: link.stats.telemetry_lost - before.telemetry_lost,
        crc_errors: link.stats.crc_errors - before.crc_errors,
        out_of_order: link.stats.telemetry_out_of_order - before.telemetry_out_of_order,
    };
    match cut {
        None => {
            write_csv(plan.out, &rows)?;
            Ok(stats(plan.out.to_owned()))
        }
        Some(cut) => {
            let file = partial(plan.out, "csv");
            let span = match (rows.first(), rows.last()) {
                (Some(a), Some(b)) => format!("samples 0 to {} (t = 0 to {:.4} s)", rows.len() - 1, b.0 - a.0),
                _ => "no samples".to_owned(),
            };
            let why = cut.describe();
            write_csv(&file, &rows)?;
            let note = format!("partial recording: {span} of {} s asked for; it ended because {why}\n", plan.seconds);
            output::write(&partial(plan.out, "txt"), note).map_err(|source| LinkError::Output { source })?;
            Err(LinkError::Partial { why, span, file, kept: stats(PathBuf::new()).samples })
        }
    }
}

/// Take telemetry into `rows` until the recording is done (`None`) or cut.
fn stream_rows(
    link: &mut Link,
    plan: &Plan<'_>,
    progress: &dyn Progress,
    rows: &mut Vec<(f64, Telemetry)>,
) -> Option<Cut> {
    let (mut t0, mut last_us, mut wraps) = (None::<f64>, 0u32, 0u64);
    let (mut next_send, mut done_ms, mut was_running) = (0.0f64, 0u64, false);
    let mut next_sync = RESYNC_PERIOD;
    let refused0 = link.stats.refused;
    // Board time must move: a stopped clock (or a board far slower than real time) ends the
    // recording after twice its length plus the silence allowance of wall time.
    let give_up = Instant::now() + Duration::from_secs_f64(2.0 * plan.seconds) + SILENT;
    let running = mode_code(Mode::Running);
    loop {
        let batch = match link.telemetry(SILENT, "recording") {
            Ok(b) => b,
            Err(e) => return Some(Cut::Link(e)),
        };
        if Instant::now() > give_up {
            let t = rows.last().map_or(0.0, |r| r.0 - t0.unwrap_or(r.0));
            return Some(Cut::ClockStopped { t });
        }
        for s in batch {
            if s.t_us < last_us {
                wraps += 1;
            }
            last_us = s.t_us;
            let t = (wraps as f64 * 4_294_967_296.0 + f64::from(s.t_us)) * 1e-6;
            let start = *t0.get_or_insert(t);
            // Half a microsecond of slack: board times are whole microseconds.
            if t - start >= plan.seconds - 0.5e-6 {
                return None;
            }
            rows.push((t, s));
            if plan.driving {
                was_running |= s.mode == running;
                if was_running && (s.mode != running || s.fault != 0) {
                    return Some(Cut::LeftLoop { t: t - start, mode: s.mode, fault: s.fault });
                }
            }
            let ms = ((t - start) * 1e3) as u64;
            progress.advance(ms.saturating_sub(done_ms));
            done_ms = done_ms.max(ms);
            if link.stats.refused > refused0 {
                let why = link.stats.last_refusal.map_or("no reason given", super::client::why);
                return Some(Cut::Refused(why.to_owned()));
            }
            if plan.driving && t - start >= next_sync {
                next_sync += RESYNC_PERIOD;
                if let Err(e) = link.resync() {
                    return Some(Cut::Link(e));
                }
            }
            if t - start >= next_send {
                if let Err(e) = keep_driving(link, plan, t - start, &mut next_send) {
                    return Some(Cut::Link(e));
                }
            }
        }
    }
}

/// The profile's reference at `t`, or a heartbeat that keeps this host's session (and
/// the drive) alive; nothing when this host does not drive.
fn keep_driving(link: &mut Link, plan: &Plan<'_>, t: f64, next_send: &mut f64) -> Result<(), LinkError> {
    if let Some(p) = plan.profile {
        *next_send = t + PROFILE_PERIOD;
        let v = quantise_reference(profile_at(p, t) as f32).unwrap_or(f32::NAN);
        link.stream_command(|guard| Command::SetTorque { guard, reference: v, ack: false })
    } else if plan.driving {
        *next_send = t + KEEPALIVE_PERIOD;
        link.stream_command(|guard| Command::Heartbeat { guard })
    } else {
        *next_send = f64::INFINITY;
        Ok(())
    }
}

fn write_csv(out: &Path, rows: &[(f64, Telemetry)]) -> Result<(), LinkError> {
    use std::io::Write as _;
    let with_true = rows.iter().any(|(_, s)| s.torque_true.is_finite());
    output::write_with(out, |w| {
        write!(w, "t,b,i,torque_est,reference,duty,mode,fault")?;
        writeln!(w, "{}", if with_true { ",torque" } else { "" })?;
        for (t, s) in rows {
            write!(
                w,
                "{t:.6},{},{},{},{},{},{},{}",
                s.b, s.current, s.torque_est, s.reference, s.duty, s.mode, s.fault
            )?;
            if with_true {
                write!(w, ",{}", s.torque_true)?;
            }
            writeln!(w)?;
        }
        Ok(())
    })
    .map_err(|source| LinkError::Output { source })
}
