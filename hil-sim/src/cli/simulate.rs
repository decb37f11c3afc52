use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use hil_sim::closed_loop::{current_driver, run, T_START};
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
    let (step, cfg) = current_driver(&sc.clutch, sc.control_hz)?;
    let pb = super::progress(1, &sc.name);
    let dur = sc.duration_s;
    let reference = |t: f64| sc.reference.at(t, dur);
    let r = run(&sc.clutch, &step, cfg, &reference, T_START + dur, sc.seed, None);
    pb.finish_and_clear();
    let every = (sc.control_hz / sc.record_hz).round().max(1.0) as usize;
    let k0 = r.after(T_START);
    let mut csv = String::from("t,b,torque,i,i_ref,duty,speed,temperature,torque_true\n");
    let mut rows = 0usize;
    for k in (k0..r.t.len()).step_by(every) {
        csv += &format!(
            "{:.5},{:.6},{:.5},{:.5},{:.5},{:.5},{:.3},{:.3},{:.5}\n",
            r.t[k] - T_START,
            r.b[k],
            r.load_cell[k],
            r.current[k],
            r.i_ref[k],
            r.duty[k],
            r.speed[k],
            r.temperature[k],
            r.torque_true[k]
        );
        rows += 1;
    }
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
