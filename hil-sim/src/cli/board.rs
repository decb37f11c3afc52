//! `hil-sim board --port PORT ACTION`: talk to a clutch driver (hil_sim::link).

use std::path::PathBuf;

use anyhow::Context;
use clap::{Args, Subcommand};
use hil_sim::link::{load, record, Link};
use model_core::control::FaultCode;
use model_core::protocol::Command;
use serde_json::json;

use super::progress::Bar;

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
    /// Bridge on (the board releases it again after 100 ms without a command).
    Enable,
    /// Bridge off.
    Disable,
    /// Clear a latched fault (the loop recalibrates).
    Reset,
    /// Set the torque reference, N·m.
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

fn fault_name(code: u8) -> &'static str {
    FaultCode::ALL.iter().find(|f| f.code() == code).map_or("unknown", |f| f.name())
}

fn ok(json: bool, what: &str) -> anyhow::Result<()> {
    if json {
        super::print_json(&json!({ "ok": true }))
    } else {
        super::emit(&format!("ok: {what}\n"));
        Ok(())
    }
}

pub fn run(a: BoardArgs) -> anyhow::Result<()> {
    let mut link = Link::open(&a.port)?;
    match a.action {
        Action::Status => {
            let s = link.status()?;
            if a.json {
                super::print_json(&json!({
                    "mode": s.mode, "fault": s.fault, "fault_name": fault_name(s.fault),
                    "overruns": s.overruns, "torque_estimate": s.torque_estimate,
                }))
            } else {
                super::emit(&format!(
                    "mode {} | fault {} ({}) | overruns {} | torque estimate {:.3} N·m\n",
                    s.mode,
                    s.fault,
                    fault_name(s.fault),
                    s.overruns,
                    s.torque_estimate
                ));
                Ok(())
            }
        }
        Action::Enable => {
            link.ack(Command::Enable(true), "enable")?;
            ok(a.json, "bridge enabled")
        }
        Action::Disable => {
            link.ack(Command::Enable(false), "disable")?;
            ok(a.json, "bridge off")
        }
        Action::Reset => {
            link.ack(Command::Reset, "reset")?;
            ok(a.json, "fault cleared")
        }
        Action::Torque { value } => {
            if !value.is_finite() {
                anyhow::bail!("torque: {value} is not a number");
            }
            link.send(Command::SetTorque(value))?;
            // Not acknowledged by the protocol; a status request confirms the board heard.
            link.status()?;
            ok(a.json, &format!("torque reference {value} N·m"))
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
            if !(seconds.is_finite() && seconds > 0.0) {
                anyhow::bail!("--seconds {seconds}: expected a positive number of seconds");
            }
            let profile = profile.map(|p| record::read_profile(&p)).transpose()?;
            if enable {
                link.ack(Command::Enable(true), "enable")?;
            }
            let bar = Bar::new(0, "record");
            let r = record::record(&mut link, seconds, &out, profile.as_deref(), decimate, &bar);
            bar.finish();
            if enable {
                link.ack(Command::Enable(false), "disable").context("after the recording")?;
            }
            let r = r?;
            if a.json {
                super::print_json(&json!({
                    "samples": r.samples, "file": r.file, "lost_frames": r.lost, "crc_errors": r.crc_errors,
                }))
            } else {
                super::emit(&format!(
                    "{}: {} samples ({} telemetry frames lost, {} dropped for a bad CRC)\n",
                    r.file.display(),
                    r.samples,
                    r.lost,
                    r.crc_errors
                ));
                Ok(())
            }
        }
    }
}
