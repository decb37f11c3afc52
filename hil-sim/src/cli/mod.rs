//! Command-line surface (shared/spec/cli-contract.md). Every subcommand takes `--json`:
//! then stdout carries exactly one JSON object; progress and logs go to stderr.

mod accuracy;
mod board;
mod budget;
mod compare;
mod demo;
mod diagnose;
mod export;
mod fit;
mod loop_cmd;
mod models;
mod progress;
mod replay;
mod simulate;
mod virtual_board;

use std::path::PathBuf;

use anyhow::bail;
use clap::{Args, Parser, Subcommand};
use hil_sim::io::recording::Channels;
use hil_sim::models::RateSpec;

#[derive(Parser, Debug)]
#[command(name = "hil-sim", version, about = "Host tooling for the MR clutch torque controller")]
pub struct Cli {
    #[command(subcommand)]
    pub cmd: Cmd,
}

#[derive(Subcommand, Debug)]
pub enum Cmd {
    /// List every model with its parameters and state size.
    Models(models::ModelsArgs),
    /// Run a recording through the no_std core in f32, one step per sample.
    Replay(replay::ReplayArgs),
    /// Identify model parameters on the first part of a recording and score the rest.
    Fit(fit::FitArgs),
    /// Seed 000's protocol: fit per recording, average the parameters, validate elsewhere.
    Compare(compare::CompareArgs),
    /// Check the f32 fixed-step core against f64 adaptive-step references.
    Accuracy(accuracy::AccuracyArgs),
    /// The main job on the bundled data (see README).
    Demo(demo::DemoArgs),
    /// Find the physics a model misses (shared/spec/physics-catalog.md), refit, and prove it held out.
    Diagnose(diagnose::DiagnoseArgs),
    /// Write a recording of the simulated MR clutch (`t,b,torque,i,…`).
    Simulate(simulate::SimulateArgs),
    /// Closed loop: the firmware's control step against the simulated clutch.
    Loop(loop_cmd::LoopArgs),
    /// Instructions, cycles and stack per step on the Cortex-M4F (QEMU mps2-an386).
    Budget(budget::BudgetArgs),
    /// Write a parameter file (`fit --save`) as the firmware's flash configuration page.
    Export(export::ExportArgs),
    /// Talk to a clutch driver: status, enable/disable, reset, torque, load, record.
    Board(board::BoardArgs),
    /// The firmware's application on the host against the simulated clutch, on a TCP port.
    VirtualBoard(virtual_board::VirtualBoardArgs),
}

pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.cmd {
        Cmd::Models(a) => models::run(a),
        Cmd::Replay(a) => replay::run(a),
        Cmd::Fit(a) => fit::run(a),
        Cmd::Compare(a) => compare::run(a),
        Cmd::Accuracy(a) => accuracy::run(a),
        Cmd::Demo(a) => demo::run(a),
        Cmd::Diagnose(a) => diagnose::run(a),
        Cmd::Simulate(a) => simulate::run_cmd(a),
        Cmd::Loop(a) => loop_cmd::run_cmd(a),
        Cmd::Budget(a) => budget::run(a),
        Cmd::Export(a) => export::run(a),
        Cmd::Board(a) => board::run(a),
        Cmd::VirtualBoard(a) => virtual_board::run(a),
    }
}

/// Channel mapping flags shared by the subcommands that read recordings.
#[derive(Args, Debug, Clone)]
pub struct ChannelArgs {
    /// Time column (seconds).
    #[arg(long, default_value = "t")]
    pub time: String,
    /// Model input column (Hall flux density for a clutch; `D` for the damper files).
    #[arg(long, default_value = "b")]
    pub input: String,
    /// Measured output column (torque for a clutch; `F` for the damper files).
    #[arg(long, default_value = "torque")]
    pub output: String,
    /// Channel driving current/voltage-dependent parameters (`Y` for the damper files).
    #[arg(long)]
    pub command: Option<String>,
    /// Rate estimator: `backward`, `filtered:FC_HZ`, `kalman[:Q:R]` (seed 002), or `auto`
    /// (each model's own choice when fitting; the parameter file's, else backward, when replaying).
    #[arg(long, default_value = "auto")]
    pub rate: String,
    /// Keep the samples the data-quality check flags (clipped, standstill, dropout,
    /// spike, non-uniform sampling) in the fit; by default they are excluded.
    #[arg(long)]
    pub keep_flagged: bool,
    /// A constant channel for a recording that lacks it, `NAME=VALUE` (e.g. `--set V=2.178`
    /// with `--command V`); repeatable.
    #[arg(long = "set", value_name = "NAME=VALUE", value_parser = parse_set)]
    pub set: Vec<(String, f64)>,
    /// List the variables of the file that are not channels (and why) on stderr.
    #[arg(long)]
    pub verbose: bool,
}

/// The recordings of a subcommand: one or several files, or a dataset manifest.
#[derive(Args, Debug, Clone)]
pub struct RecordingArgs {
    /// Recording(s): CSV/text or level-5 MAT-files; several are identified as one dataset
    /// (the model restarts at each, parameters are shared).
    #[arg(required_unless_present = "dataset")]
    pub recs: Vec<PathBuf>,
    /// A dataset manifest (TOML: `[channels]` defaults and one `[[run]]` per recording with
    /// its `file`, `set` and `role` = train|validate; see README).
    #[arg(long, value_name = "TOML", conflicts_with = "recs")]
    pub dataset: Option<PathBuf>,
    /// Let the manifest's runs name files outside its folder (absolute paths, `..`).
    #[arg(long, requires = "dataset")]
    pub allow_outside: bool,
}

impl RecordingArgs {
    /// The runs named, each with its channels (the manifest's over `ch`'s).
    pub fn runs(&self, ch: &Channels) -> anyhow::Result<Vec<hil_sim::ident::runs::RunSpec>> {
        use hil_sim::ident::runs::{from_manifest, RunSpec};
        use hil_sim::io::manifest::RunPaths;
        if let Some(m) = &self.dataset {
            let paths = if self.allow_outside { RunPaths::Anywhere } else { RunPaths::InsideFolder };
            let runs = from_manifest(&file_arg(m)?, ch, paths)?;
            for r in &runs {
                file_arg(&r.path).map_err(|e| anyhow::anyhow!("{}: run {e}", m.display()))?;
            }
            return Ok(runs);
        }
        self.recs
            .iter()
            .map(|p| Ok(RunSpec { path: file_arg(p)?, channels: ch.clone(), role: hil_sim::io::manifest::Role::Train }))
            .collect()
    }

    /// How the recordings are named in messages: the file, or the manifest.
    pub fn label(&self) -> String {
        match (&self.dataset, self.recs.as_slice()) {
            (Some(m), _) => m.display().to_string(),
            (None, [one]) => one.display().to_string(),
            (None, many) => format!("{} recordings", many.len()),
        }
    }
}

/// `NAME=VALUE`, the syntax of `--set`.
pub fn parse_set(s: &str) -> Result<(String, f64), String> {
    let (name, value) = s.split_once('=').ok_or_else(|| format!("`{s}`: expected NAME=VALUE (e.g. V=2.178)"))?;
    let v: f64 = value.trim().parse().map_err(|_| format!("`{s}`: `{value}` is not a number"))?;
    if name.trim().is_empty() || !v.is_finite() {
        return Err(format!("`{s}`: expected NAME=VALUE with a finite value"));
    }
    Ok((name.trim().to_owned(), v))
}

/// With `--verbose`, the variables of `rec` that are not channels, one line each on stderr.
pub fn list_skipped(verbose: bool, rec: &hil_sim::io::recording::Recording) {
    if verbose {
        for s in &rec.skipped {
            eprintln!("note: {}: skipped {}", rec.path.display(), s.reason);
        }
    }
}

impl ChannelArgs {
    pub fn channels(&self) -> Channels {
        Channels {
            time: self.time.clone(),
            input: self.input.clone(),
            output: self.output.clone(),
            command: self.command.clone(),
            set: self.set.clone(),
        }
    }
    /// The rate estimator named by `--rate`; `None` for `auto`.
    pub fn rate(&self) -> anyhow::Result<Option<RateSpec>> {
        if self.rate == "auto" {
            Ok(None)
        } else {
            parse_rate(&self.rate).map(Some)
        }
    }
}

pub fn parse_rate(s: &str) -> anyhow::Result<RateSpec> {
    hil_sim::io::rate::parse(s).map_err(|e| anyhow::anyhow!("--rate {e}"))
}

/// Print one JSON object on stdout.
pub fn print_json(v: &serde_json::Value) -> anyhow::Result<()> {
    emit(&(serde_json::to_string_pretty(v)? + "\n"));
    Ok(())
}

/// Write to stdout; a closed pipe (`hil-sim … | head`) ends the program quietly.
pub fn emit(text: &str) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        eprintln!("error: writing to stdout: {e}");
        std::process::exit(1);
    }
}

/// A progress bar on stderr (hidden when stderr is not a terminal or under `--json`
/// piping; indicatif handles that).
pub fn progress(len: u64, what: &str) -> indicatif::ProgressBar {
    let pb = indicatif::ProgressBar::new(len);
    pb.set_style(
        indicatif::ProgressStyle::with_template("{msg:>12} [{bar:40}] {pos}/{len} {elapsed_precise}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    pb.set_message(what.to_owned());
    pb
}

pub fn file_arg(p: &std::path::Path) -> anyhow::Result<PathBuf> {
    if p.is_file() {
        Ok(p.to_path_buf())
    } else {
        bail!("{}: no such file", p.display())
    }
}

/// `v` with `decimals` decimals, or `undefined` when it is not a number (e.g. R² of a
/// constant output, which has no variance to explain).
pub fn fixed(v: f64, decimals: usize) -> String {
    if v.is_nan() {
        "undefined".into()
    } else {
        format!("{v:.decimals$}")
    }
}

/// The warning for a constant output channel (R² and GOF undefined), if it is one.
pub fn constant_output(name: &str, y: &[f64]) -> Option<String> {
    let v = y.first()?;
    y.iter().all(|x| x == v).then(|| {
        format!("the output `{name}` is constant ({v}): R² and GOF are undefined (there is no variance to explain)")
    })
}
