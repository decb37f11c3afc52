use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use hil_sim::scenario::{Quantity, Scenario, BUILTIN};
use serde_json::json;

#[derive(Args, Debug)]
pub struct SimulateArgs {
    /// Built-in scenario name or a TOML scenario file.
    #[arg(long)]
    pub scenario: String,
    /// CSV recording to write (`t,b,torque,i,…`).
    #[arg(long)]
    pub out: PathBuf,
    #[arg(long)]
    pub json: bool,
}

pub fn run_cmd(a: SimulateArgs) -> anyhow::Result<()> {
    let sc = Scenario::load(&a.scenario)?;
    if sc.reference.quantity != Quantity::Current {
        anyhow::bail!(
            "scenario `{}`: simulate drives the coil current; a torque reference needs `hil-sim loop` (built-in: {})",
            sc.name,
            BUILTIN.join(", ")
        );
    }
    let pb = super::progress(1, &sc.name);
    let rec = sc.record()?;
    pb.finish_and_clear();
    let (csv, rows, r, k0) = (rec.csv, rec.rows, rec.run, rec.first);
    if let Some(dir) = a.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    std::fs::write(&a.out, csv).with_context(|| format!("writing {}", a.out.display()))?;
    let (tmin, tmax) = r.torque_true[k0..].iter().fold((f64::MAX, f64::MIN), |(lo, hi), v| (lo.min(*v), hi.max(*v)));
    let theta_end = r.temperature.last().copied().unwrap_or(f64::NAN);
    if a.json {
        return super::print_json(&json!({
            "scenario": sc.name, "description": sc.description, "out": a.out, "rows": rows,
            "record_hz": sc.record_hz, "control_hz": sc.control_hz,
            "torque_range": [tmin, tmax], "temperature_end_c": theta_end,
            "columns": ["t", "b", "torque", "i", "i_ref", "duty", "speed", "temperature", "torque_true"],
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
