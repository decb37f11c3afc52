//! `hil-sim loop`: the firmware's control step against the simulated clutch (computation in
//! `hil_sim::closed_loop::evaluate`; this file parses flags, writes CSV files and prints).

use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::{Args, ValueEnum};
use hil_sim::closed_loop::{evaluate, LoopReport, LoopScenario, LoopSpec, Run, ScenarioFigures};
use hil_sim::sim::plant::ClutchParams;
use hil_sim::sim::scenario::Scenario;
use serde_json::{json, Value};

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LoopScenarioArg {
    /// Torque reference: seed 000 eq. 21 multi-sine mapped to 2–10 N·m, 20 s.
    Multisine,
    /// Torque steps 2 → 8 → 4 → 10 → 0 → 6 N·m, 0.25 s each.
    Steps,
    /// Stepped sines 2–500 Hz, ±1 N·m around 6 N·m: the −3 dB bandwidth.
    Sweep,
    /// 90 s at 60 rad/s slip, 7 ± 2 N·m at 1 Hz: error drift as the fluid heats.
    Heating,
    /// Each fault injected alone at 0.3 s into a multi-sine run.
    Faults,
}

impl From<LoopScenarioArg> for LoopScenario {
    fn from(a: LoopScenarioArg) -> Self {
        match a {
            LoopScenarioArg::Multisine => Self::Multisine,
            LoopScenarioArg::Steps => Self::Steps,
            LoopScenarioArg::Sweep => Self::Sweep,
            LoopScenarioArg::Heating => Self::Heating,
            LoopScenarioArg::Faults => Self::Faults,
        }
    }
}

/// `--control-hz`'s default for the scenarios, Hz.
const DEFAULT_CONTROL_HZ: f64 = 10_000.0;

/// The longest `--replay`, samples (every one is kept for the trace).
const MAX_REPLAY_SAMPLES: f64 = 3_600_000.0;

/// `--duration`'s default for the multisine run, s.
const DEFAULT_MULTISINE_S: f64 = 20.0;

#[derive(Args, Debug)]
pub struct LoopArgs {
    #[arg(long, value_enum, required_unless_present = "replay")]
    pub scenario: Option<LoopScenarioArg>,
    /// Replay a virtual board's session instead of a scenario: its `--journal` file (what
    /// it applied at which sample), on the same clutch, seed and bench, with the page of
    /// `--params` swapped in at the journal's `page` event; every sample to `--trace`.
    #[arg(long, requires_all = ["params", "trace", "duration"], conflicts_with = "scenario")]
    pub replay: Option<PathBuf>,
    /// `fit --save` parameter file of the page the board loaded (with `--replay`).
    #[arg(long, requires = "replay")]
    pub params: Option<PathBuf>,
    /// CSV of every replayed sample, `t,reference,torque_est,torque,enable,fault` (with
    /// `--replay`).
    #[arg(long, requires = "replay")]
    pub trace: Option<PathBuf>,
    /// Fault injected in the replay, NAME@SECONDS (as `virtual-board --fault`).
    #[arg(long, requires = "replay")]
    pub fault: Option<String>,
    /// TOML scenario file whose `[clutch]` replaces the reference clutch.
    #[arg(long)]
    pub clutch: Option<PathBuf>,
    /// Folder for CSV files of the runs (`t,reference,torque_est,torque,i,i_ref,duty,…`).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Control-step rate, Hz.
    /// (default 10 000 for the scenarios; with `--replay`, the rate the board runs the page's
    /// model at, `firmware::runner`, and only that).
    #[arg(long)]
    pub control_hz: Option<f64>,
    /// Duration of the multisine run, s (default 20; the other scenarios have fixed
    /// lengths); with `--replay`, the simulated seconds replayed.
    #[arg(long)]
    pub duration: Option<f64>,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    #[arg(long)]
    pub json: bool,
}

fn write_csv(dir: &Option<PathBuf>, name: &str, r: &Run) -> anyhow::Result<()> {
    if let Some(d) = dir {
        hil_sim::io::output::write(&d.join(name), r.csv())?;
    }
    Ok(())
}

pub fn run_cmd(a: LoopArgs) -> anyhow::Result<()> {
    let clutch = match &a.clutch {
        Some(p) => {
            Scenario::parse(p, &std::fs::read_to_string(p).with_context(|| format!("reading {}", p.display()))?)?.clutch
        }
        None => ClutchParams::default(),
    };
    let Some(scenario) = a.scenario else { return replay(&a, &clutch) };
    let scenario: LoopScenario = scenario.into();
    let duration = match (a.duration, scenario) {
        (None, _) => DEFAULT_MULTISINE_S,
        (Some(d), LoopScenario::Multisine) => d,
        (Some(_), other) => {
            anyhow::bail!("--duration applies to --scenario multisine only; `{}` has a fixed length", other.name())
        }
    };
    let control_hz = a.control_hz.unwrap_or(DEFAULT_CONTROL_HZ);
    let spec = LoopSpec { scenario, control_hz, duration, seed: a.seed };
    let bar = super::progress::Bar::new(3, "identify");
    let report = evaluate(&clutch, &spec, &bar)?;
    bar.finish();
    let name = report.scenario.name();
    match &report.figures {
        ScenarioFigures::Heating { temp_comp_run, .. } => {
            write_csv(&a.out, "heating_loop_temp_comp.csv", temp_comp_run)?
        }
        ScenarioFigures::Faults { results } => {
            for (f, r) in results {
                write_csv(&a.out, &format!("fault_{}.csv", f.fault), r)?;
            }
        }
        _ => {}
    }
    write_csv(&a.out, &format!("{name}_loop.csv"), &report.loop_run)?;
    write_csv(&a.out, &format!("{name}_baseline.csv"), &report.baseline_run)?;
    if a.json {
        return super::print_json(&report_json(&report, control_hz));
    }
    print_text(&report, control_hz);
    if let Some(d) = &a.out {
        super::emit(&format!("  CSV written to {}\n", Path::new(d).display()));
    }
    Ok(())
}

/// `loop --replay JOURNAL --params P --trace OUT --duration S`.
fn replay(a: &LoopArgs, clutch: &ClutchParams) -> anyhow::Result<()> {
    use hil_sim::closed_loop::replay::{csv, parse_journal, replay};
    use hil_sim::io::{config_page, params_file::ParamsFile};
    let (Some(journal), Some(params), Some(trace), Some(duration)) = (&a.replay, &a.params, &a.trace, a.duration)
    else {
        anyhow::bail!("--replay needs --params, --trace and --duration")
    };
    let events = parse_journal(
        &std::fs::read_to_string(journal).with_context(|| format!("reading --replay {}", journal.display()))?,
    )
    .with_context(|| format!("--replay {}", journal.display()))?;
    let file = ParamsFile::read(params)?;
    // The rate the board runs the page's model at (the page must be the one it loaded).
    let (control_hz, control) = config_page::firmware_control(&file.model, a.control_hz.map(|hz| hz as f32))?;
    let page = config_page::firmware_image(&file, params, control)?;
    let fault = a.fault.as_deref().map(super::virtual_board::parse_fault).transpose()?;
    if !(duration.is_finite() && duration > 0.0) {
        anyhow::bail!("--duration {duration}: expected a positive number of seconds");
    }
    // At most this many samples: the board boots at the fastest rate.
    let samples = (duration * f64::from(config_page::CONTROL_HZ.max(control_hz))).round();
    if !(1.0..=MAX_REPLAY_SAMPLES).contains(&samples) {
        anyhow::bail!(
            "--duration {duration} s: up to {samples} samples; a replay runs 1 to {MAX_REPLAY_SAMPLES} (3 min at 20 kHz)"
        );
    }
    let rows = replay(clutch, a.seed, fault, &events, &page, duration)
        .with_context(|| format!("--replay {}", journal.display()))?;
    hil_sim::io::output::write(trace, csv(&rows))?;
    if a.json {
        return super::print_json(&json!({
            "replay": journal, "samples": rows.len(), "control_hz": f64::from(control_hz), "page_crc": format!("{:#010x}", page.crc()), "trace": trace,
        }));
    }
    super::emit(&format!(
        "loop --replay {}: {} samples at {} Hz, page {:#010x}; trace written to {}\n",
        journal.display(),
        rows.len(),
        control_hz,
        page.crc(),
        trace.display()
    ));
    Ok(())
}

/// The `--json` object.
fn report_json(r: &LoopReport, control_hz: f64) -> Value {
    let faults: Vec<_> = match &r.figures {
        ScenarioFigures::Faults { results } => results.iter().map(|(f, _)| f).collect(),
        _ => Vec::new(),
    };
    let mut v = json!({
        "scenario": r.scenario.name(), "control_hz": control_hz,
        "identified": r.identified,
        "tracking": r.tracking, "baseline": r.baseline, "improvement_r_rmse": r.improvement_r_rmse,
        "faults": faults,
    });
    let extra = match &r.figures {
        ScenarioFigures::Multisine | ScenarioFigures::Faults { .. } => json!({}),
        ScenarioFigures::Steps { rises } => json!({"rise_10_90": rises}),
        ScenarioFigures::Sweep { bandwidth_loop, bandwidth_baseline, response_loop, response_baseline } => json!({
            "bandwidth_hz": {"loop": bandwidth_loop, "baseline": bandwidth_baseline},
            "response": {"loop": response_loop, "baseline": response_baseline}}),
        ScenarioFigures::Heating { windows, tracking_temp_comp, .. } => {
            json!({"heating": windows, "tracking_temp_comp": tracking_temp_comp})
        }
    };
    if let (Some(o), Some(e)) = (v.as_object_mut(), extra.as_object()) {
        o.extend(e.clone());
    }
    v
}

/// The scenario's own lines of the text report.
fn scenario_text(f: &ScenarioFigures) -> String {
    let mut text = String::new();
    match f {
        ScenarioFigures::Multisine | ScenarioFigures::Steps { .. } => {}
        ScenarioFigures::Sweep { bandwidth_loop, bandwidth_baseline, response_loop, response_baseline } => {
            text += &format!(
                "  -3 dB bandwidth of the true torque: loop {} Hz, baseline {} Hz\n",
                bandwidth_loop.map_or("> 500".into(), |v| format!("{v:.0}")),
                bandwidth_baseline.map_or("> 500".into(), |v| format!("{v:.0}"))
            );
            for (p, q) in response_loop.iter().zip(response_baseline) {
                text += &format!("    {:>5.0} Hz  loop {:.3}  baseline {:.3}\n", p.f_hz, p.gain, q.gain);
            }
        }
        ScenarioFigures::Heating { windows, .. } => {
            text += "  window    θ (°C)   mean error (N·m) / R-RMSE: loop | loop+temp comp | baseline\n";
            for w in windows {
                let (l, c, b) = (w.closed_loop, w.loop_temp_comp, w.baseline);
                text += &format!(
                    "  {:>2}-{:<3}s  {:6.1}   {:+.3} / {:5.2} % | {:+.3} / {:5.2} % | {:+.3} / {:5.2} %\n",
                    w.t0_s,
                    w.t1_s,
                    w.temperature_c,
                    l.mean_error,
                    100.0 * l.r_rmse,
                    c.mean_error,
                    100.0 * c.r_rmse,
                    b.mean_error,
                    100.0 * b.r_rmse
                );
            }
        }
        ScenarioFigures::Faults { results } => {
            text += "  fault          detected  detect_ms  safe_state  code\n";
            for (f, _) in results {
                text += &format!(
                    "  {:<14} {:<9} {:>9} {:<11} {} ({})\n",
                    f.fault,
                    f.detected,
                    f.detect_ms.map_or("-".into(), |v| format!("{v:.2}")),
                    f.safe_state,
                    f.code,
                    f.code_name
                );
            }
        }
    }
    text
}

fn print_text(r: &LoopReport, control_hz: f64) {
    let (tm, bm) = (&r.tracking, &r.baseline);
    super::emit(&format!(
        "loop --scenario {} at {} Hz (algebraic model fitted on the simulated clutch: R-RMSE {:.2} %)\n",
        r.scenario.name(),
        control_hz,
        100.0 * r.identified.algebraic_fit_r_rmse
    ));
    super::emit(&format!(
        "  true torque vs reference: loop R-RMSE {:.2} % (R² {:.4}), baseline R-RMSE {:.2} % (R² {:.4}), {:.1}× lower\n",
        100.0 * tm.r_rmse,
        tm.r2,
        100.0 * bm.r_rmse,
        bm.r2,
        r.improvement_r_rmse
    ));
    super::emit(&scenario_text(&r.figures));
}
