use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use hil_sim::sim::concealed::{generate, ConcealedError, ConcealedSpec};
use hil_sim::sim::scenario::{Quantity, Scenario, BUILTIN};
use serde_json::json;

#[derive(Args, Debug)]
#[command(group(clap::ArgGroup::new("what").required(true).args(["scenario", "effect"])))]
pub struct SimulateArgs {
    /// Built-in scenario name or a TOML scenario file (the simulated clutch in closed loop).
    #[arg(long)]
    pub scenario: Option<String>,
    /// Instead of a scenario: a recording with one concealed catalog effect (or `none`), for
    /// proving `diagnose` blind: none, field_lag, transport_delay, saturation,
    /// rate_dependence, asymmetry, thermal_drift, slip_speed, inertia, aux_dependence,
    /// sensor_offset. Columns `t,b,torque,i,speed,temperature`.
    #[arg(long)]
    pub effect: Option<String>,
    /// With --effect: the truth's model (algebraic, bouc_wen, lugre, tanh, dahl).
    #[arg(long, default_value = "bouc_wen", requires = "effect")]
    pub base: String,
    /// With --effect: the field excitation (multisine, noise, sweep, triangle).
    #[arg(long, default_value = "multisine", requires = "effect")]
    pub excitation: String,
    /// With --effect: RMS of the effect's change to the torque, fraction of its span.
    #[arg(long, default_value_t = 0.04, requires = "effect")]
    pub size: f64,
    /// With --effect: random seed (phases, noise).
    #[arg(long, default_value_t = 1, requires = "effect")]
    pub seed: u64,
    /// With --effect: length, seconds.
    #[arg(long, default_value_t = 30.0, requires = "effect")]
    pub duration: f64,
    /// With --effect: sampling rate, Hz.
    #[arg(long, default_value_t = 2000.0, requires = "effect")]
    pub fs: f64,
    /// With --effect: write what was concealed (effect, true values) to this JSON file; the
    /// recording itself never says.
    #[arg(long, requires = "effect")]
    pub label: Option<PathBuf>,
    /// CSV recording to write (`t,b,torque,i,…`).
    #[arg(long)]
    pub out: PathBuf,
    #[arg(long)]
    pub json: bool,
}

fn write(path: &std::path::Path, text: &str) -> anyhow::Result<()> {
    Ok(hil_sim::io::output::write(path, text)?)
}

/// Create `path`'s folder and write `path` with `write`.
fn write_with(
    path: &std::path::Path,
    write: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> std::io::Result<()>,
) -> anyhow::Result<()> {
    Ok(hil_sim::io::output::write_with(path, write)?)
}

/// The generator's error with the flags that set the offending values.
fn flagged(e: ConcealedError) -> anyhow::Error {
    match e {
        ConcealedError::Size(v) => {
            anyhow::anyhow!("--size {v}: must be between 0 and 0.5 (a fraction of the torque span)")
        }
        ConcealedError::Length(d, fs) => {
            anyhow::anyhow!("--duration {d} s at --fs {fs} Hz: need at least 2 s and 200 Hz, at most 10^7 samples")
        }
        e => e.into(),
    }
}

fn run_concealed(a: &SimulateArgs, effect: &str) -> anyhow::Result<()> {
    let spec = ConcealedSpec {
        effect: effect.to_owned(),
        base: a.base.clone(),
        excitation: a.excitation.clone(),
        size: a.size,
        seed: a.seed,
        duration_s: a.duration,
        fs_hz: a.fs,
    };
    let pb = super::progress(1, "generating");
    let g = generate(&spec);
    pb.finish_and_clear();
    let g = g.map_err(flagged)?;
    write_with(&a.out, |w| g.recording.write_csv(w))?;
    if let Some(l) = &a.label {
        write(l, &(serde_json::to_string_pretty(&g.label)? + "\n"))?;
    }
    let rows = (a.duration * a.fs).round() as usize;
    if a.json {
        return super::print_json(&json!({
            "out": a.out, "rows": rows, "fs_hz": a.fs, "label_file": a.label,
            "columns": ["t", "b", "torque", "i", "speed", "temperature"],
            "torque_span_nm": g.label.torque_span_nm,
        }));
    }
    super::emit(&format!(
        "{} rows at {} Hz ({} base, {} excitation) -> {}{}\n",
        rows,
        a.fs,
        a.base,
        a.excitation,
        a.out.display(),
        a.label.as_ref().map(|l| format!("; label in {}", l.display())).unwrap_or_default()
    ));
    Ok(())
}

pub fn run_cmd(a: SimulateArgs) -> anyhow::Result<()> {
    let name = match (&a.scenario, &a.effect) {
        (_, Some(effect)) => return run_concealed(&a, effect),
        (Some(s), None) => s.clone(),
        (None, None) => anyhow::bail!("give --scenario NAME or --effect EFFECT"),
    };
    let sc = Scenario::load(&name)?;
    if sc.reference.quantity != Quantity::Current {
        anyhow::bail!(
            "scenario `{}`: simulate drives the coil current; a torque reference needs `hil-sim loop` (built-in: {})",
            sc.name,
            BUILTIN.join(", ")
        );
    }
    let pb = super::progress(1, &sc.name);
    let rec = hil_sim::closed_loop::record::record(&sc).with_context(|| format!("simulating {name}"))?;
    pb.finish_and_clear();
    let (rows, r, k0) = (rec.recording.len(), &rec.run, rec.first);
    hil_sim::io::output::write_with(&a.out, |w| rec.recording.write_csv(w))?;
    let (tmin, tmax) = r.torque_true[k0..].iter().fold((f64::MAX, f64::MIN), |(lo, hi), v| (lo.min(*v), hi.max(*v)));
    let theta_end = r.temperature.last().copied().unwrap_or(f64::NAN);
    if a.json {
        return super::print_json(&json!({
            "scenario": sc.name, "description": sc.description, "out": a.out, "rows": rows,
            "record_hz": sc.record_hz, "control_hz": sc.control_hz,
            "torque_range": [tmin, tmax], "temperature_end_c": theta_end,
            "columns": hil_sim::closed_loop::record::RECORD_COLUMNS,
        }));
    }
    super::emit(&format!(
        "{}: {} ({} rows at {} Hz) -> {}\n  torque {:.2}..{:.2} N·m, temperature at end {:.1} °C\n",
        sc.name,
        sc.description,
        rows,
        sc.record_hz,
        a.out.display(),
        tmin,
        tmax,
        theta_end
    ));
    Ok(())
}
