//! `hil-sim board --port PORT ACTION`: talk to a clutch driver (hil_sim::link).

use std::path::PathBuf;

use anyhow::{bail, Context};
use clap::{Args, Subcommand};
use hil_sim::link::client::{fault_name, mode_name};
use hil_sim::link::{load, record, Link, LinkError};
use model_core::protocol::{quantise_reference, Command, Nack};
use serde_json::json;

use super::progress::Bar;

/// A reset is answered once the fault checks have had their samples: up to 50 ms on the
/// board, plus the line.
const RESET_REPLY: std::time::Duration = std::time::Duration::from_millis(500);

#[derive(Args, Debug)]
pub struct BoardArgs {
    /// Serial device (the Nucleo's ST-LINK port, e.g. /dev/ttyACM0), tcp:HOST:PORT (the
    /// virtual board) or can:IFACE.
    #[arg(long)]
    pub port: String,
    #[arg(long, global = true)]
    pub json: bool,
    #[command(subcommand)]
    pub action: Action,
}

#[derive(Subcommand, Debug)]
pub enum Action {
    /// Mode, latched fault, overruns, torque estimate.
    Status,
    /// Bridge on (the board releases it again after 100 ms without a command from this
    /// host; refused while a fault is latched).
    Enable,
    /// Bridge off.
    Disable,
    /// Clear a latched fault (the loop recalibrates); fails if the fault is still present.
    Reset,
    /// Set the torque reference, N·m (within the running page's limit; 1 mN·m steps).
    Torque {
        #[arg(allow_negative_numbers = true)]
        value: f32,
    },
    /// Load a `fit --save` file: configuration page, transfer, check, commit, verify.
    Load { params: PathBuf },
    /// Stream the board's signals to a CSV recording (`fit`, `replay` and `diagnose` read it).
    Record {
        #[arg(long)]
        seconds: f64,
        #[arg(long)]
        out: PathBuf,
        /// Play a torque-reference profile meanwhile (CSV `t,reference`, s and N·m).
        #[arg(long)]
        profile: Option<PathBuf>,
        /// Stream every n-th control sample (the UART carries about 2 kHz of frames).
        #[arg(long, default_value_t = 10)]
        decimate: u16,
        /// Enable the bridge when the recording starts and disable it at the end.
        #[arg(long)]
        enable: bool,
    },
}

fn ok(json: bool, what: &str) -> anyhow::Result<()> {
    if json {
        super::print_json(&json!({ "ok": true }))
    } else {
        super::emit(&format!("ok: {what}\n"));
        Ok(())
    }
}

/// A refusal that names the fault it is about (read from the board's status).
fn with_fault(link: &mut Link, e: LinkError) -> anyhow::Error {
    match &e {
        LinkError::Refused { reason: Nack::Faulted | Nack::FaultPresent, .. } => match link.status() {
            Ok(s) => anyhow::anyhow!("{e}: latched fault {} (code {})", fault_name(s.fault), s.fault),
            Err(_) => e.into(),
        },
        _ => e.into(),
    }
}

/// A reference within the running page's limit, as the frame carries it.
fn checked_reference(link: &mut Link, value: f32) -> anyhow::Result<f32> {
    let limits = link.limits()?;
    match quantise_reference(value) {
        Some(v) if v.abs() <= limits.reference_max => Ok(v),
        _ => bail!(
            "torque {value:?}: beyond the running page's limit of ±{} N·m (its torque_max); nothing was sent",
            limits.reference_max
        ),
    }
}

pub fn run(a: BoardArgs) -> anyhow::Result<()> {
    let mut link = Link::open(&a.port)?;
    match a.action {
        Action::Status => {
            let s = link.status()?;
            if a.json {
                super::print_json(&json!({
                    "mode": s.mode, "mode_name": mode_name(s.mode), "fault": s.fault, "fault_name": fault_name(s.fault),
                    "overruns": s.overruns, "torque_estimate": s.torque_estimate,
                }))
            } else {
                super::emit(&format!(
                    "mode {} | fault {} | overruns {} | torque estimate {:.3} N·m\n",
                    mode_name(s.mode),
                    if s.fault == 0 {
                        "none".to_owned()
                    } else {
                        format!("{} (code {})", fault_name(s.fault), s.fault)
                    },
                    s.overruns,
                    s.torque_estimate
                ));
                Ok(())
            }
        }
        Action::Enable => {
            let r = link.command(|guard| Command::Enable { guard, on: true }, "enable");
            r.map_err(|e| with_fault(&mut link, e))?;
            ok(a.json, "bridge enabled")
        }
        Action::Disable => {
            link.command(|guard| Command::Enable { guard, on: false }, "disable")?;
            ok(a.json, "bridge off")
        }
        Action::Reset => {
            let r = link.command_waiting(|guard| Command::Reset { guard }, "reset", RESET_REPLY);
            r.map_err(|e| with_fault(&mut link, e))?;
            ok(a.json, "fault cleared")
        }
        Action::Torque { value } => {
            let v = checked_reference(&mut link, value)?;
            link.command(|guard| Command::SetTorque { guard, reference: v, ack: true }, "the torque reference")?;
            ok(a.json, &format!("torque reference {v} N·m"))
        }
        Action::Load { params } => {
            let path = super::file_arg(&params)?;
            let bar = Bar::new(0, "load");
            let r = load::load(&mut link, &path, &bar);
            bar.finish();
            let r = r?;
            if a.json {
                super::print_json(
                    &json!({ "ok": true, "bytes": r.bytes, "crc": format!("{:#010x}", r.crc), "model": r.model }),
                )
            } else {
                super::emit(&format!(
                    "ok: {} loaded ({} bytes, CRC-32 {:#010x}), committed and verified\n",
                    r.model, r.bytes, r.crc
                ));
                Ok(())
            }
        }
        Action::Record { seconds, out, profile, decimate, enable } => {
            // The profile is read first: it is an input, which no output may overwrite.
            let profile = profile.map(|p| record::read_profile(&p).map(|rows| (p, rows))).transpose()?;
            record::check_request(seconds, decimate, &out)?;
            if let Some((p, rows)) = &profile {
                record::check_profile(p, rows, &link.limits()?)?;
            }
            let profile = profile.map(|(_, rows)| rows);
            if enable {
                link.command(|guard| Command::Enable { guard, on: true }, "enable")
                    .map_err(|e| with_fault(&mut link, e))?;
            }
            let bar = Bar::new(0, "record");
            let plan = record::Plan {
                seconds,
                out: &out,
                profile: profile.as_deref(),
                decimation: decimate,
                driving: enable || profile.is_some(),
            };
            let r = record::record(&mut link, &plan, &bar);
            bar.finish();
            if enable {
                link.command(|guard| Command::Enable { guard, on: false }, "disable").context("after the recording")?;
            }
            let r = r?;
            if a.json {
                super::print_json(&json!({
                    "samples": r.samples, "file": r.file, "lost_frames": r.lost, "crc_errors": r.crc_errors,
                    "out_of_order": r.out_of_order,
                }))
            } else {
                super::emit(&format!(
                    "{}: {} samples ({} telemetry frames lost, {} dropped for a bad CRC, {} out of order)\n",
                    r.file.display(),
                    r.samples,
                    r.lost,
                    r.crc_errors,
                    r.out_of_order
                ));
                Ok(())
            }
        }
    }
}
