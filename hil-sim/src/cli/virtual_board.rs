//! `hil-sim virtual-board --listen tcp:HOST:PORT`: the firmware's application on the host
//! (hil_sim::virtual_board).

use std::path::PathBuf;

use anyhow::{bail, Context};
use clap::Args;
use hil_sim::closed_loop::{Injection, Schedule};
use hil_sim::sim::plant::ClutchParams;
use hil_sim::sim::scenario::Scenario;
use hil_sim::virtual_board::{serve, ServeOptions};

#[derive(Args, Debug)]
pub struct VirtualBoardArgs {
    /// Address to answer on, tcp:HOST:PORT (port 0: a free one; the address is printed).
    #[arg(long)]
    pub listen: String,
    /// Simulation scenario (built-in name or TOML file) whose clutch and noise seed the
    /// plant uses (default: the reference clutch, seed 1).
    #[arg(long)]
    pub scenario: Option<String>,
    /// Inject a fault at a time, NAME@SECONDS (the faults of `loop --scenario faults`).
    #[arg(long)]
    pub fault: Option<String>,
    /// Write what was applied at which sample (`K ref V`, `K enable 1`, `K page CRC`, …).
    #[arg(long)]
    pub journal: Option<PathBuf>,
    /// Stall the application's tasks from this simulated time on, s: the modelled watchdog
    /// (50 ms) resets the board, which starts again from flash (the plant keeps running).
    #[arg(long)]
    pub stall_tasks: Option<f64>,
}

/// `--fault NAME@SECONDS` (also `loop --replay`).
pub(super) fn parse_fault(s: &str) -> anyhow::Result<Schedule> {
    let names = || Injection::ALL.iter().map(|i| i.name()).collect::<Vec<_>>().join(", ");
    let Some((name, at)) = s.split_once('@') else { bail!("--fault `{s}`: expected NAME@SECONDS (NAME: {})", names()) };
    let Some(injection) = Injection::ALL.into_iter().find(|i| i.name() == name) else {
        bail!("--fault `{s}`: unknown fault `{name}` (one of {})", names())
    };
    match at.parse::<f64>() {
        Ok(at) if at.is_finite() && at >= 0.0 => Ok(Schedule { injection, at }),
        _ => bail!("--fault `{s}`: `{at}` is not a time in seconds"),
    }
}

pub fn run(a: VirtualBoardArgs) -> anyhow::Result<()> {
    let fault = a.fault.as_deref().map(parse_fault).transpose()?;
    let (clutch, seed) = match &a.scenario {
        Some(name) => {
            let s = Scenario::load(name)?;
            (s.clutch, s.seed)
        }
        None => (ClutchParams::default(), 1),
    };
    let journal: hil_sim::virtual_board::Journal = match &a.journal {
        Some(p) => {
            Some(Box::new(hil_sim::io::output::create_stream(p).with_context(|| format!("--journal {}", p.display()))?))
        }
        None => None,
    };
    if let Some(t) = a.stall_tasks.filter(|t| !(t.is_finite() && *t >= 0.0)) {
        bail!("--stall-tasks {t}: expected a time in seconds");
    }
    let opts = ServeOptions { listen: a.listen, clutch, seed, fault, journal, stall_tasks: a.stall_tasks };
    serve(opts, &mut |addr| {
        eprintln!("virtual board listening on tcp:{addr}");
        eprintln!("ready");
    })?;
    Ok(())
}
