use clap::Args;
use hil_sim::sim::accuracy::{self, Row, MAX_R_RMSE};
use serde_json::json;

#[derive(Args, Debug)]
pub struct AccuracyArgs {
    /// Only this model.
    #[arg(long)]
    pub model: Option<String>,
    /// Shorter multi-sine and swept-sine runs (a quarter of the duration).
    #[arg(long)]
    pub quick: bool,
    /// Skip the case on the real Dyke recording.
    #[arg(long)]
    pub no_recording: bool,
    #[arg(long)]
    pub json: bool,
}

/// Run the check (only `model` when given, `quick` runs, with or without the Dyke
/// recording); returns the rows (also used by `demo`).
pub fn rows(model: Option<&str>, quick: bool, no_recording: bool) -> anyhow::Result<Vec<Row>> {
    let rec = if no_recording {
        None
    } else {
        let path = hil_sim::io::bundled::data_file("dyke/ranran_50.csv").map_err(anyhow::Error::msg)?;
        Some(accuracy::load_dyke(&path)?)
    };
    if let Some(m) = model {
        if model_core::registry::find(m).is_none() {
            anyhow::bail!("unknown model `{m}` (see `hil-sim models`)");
        }
    }
    let n = accuracy::count_jobs(model, quick, rec.is_some());
    if n == 0 {
        anyhow::bail!(
            "no accuracy cases for {}: it has no ODE (stateless or exact operator models need none)",
            model.unwrap_or("any model")
        );
    }
    let bar = super::progress::Bar::new(n as u64, "accuracy");
    let rows = accuracy::run_all(model, quick, rec.as_ref(), &bar)?;
    bar.finish();
    Ok(rows)
}

pub fn table(rows: &[Row]) -> String {
    let mut s = format!(
        "{:<14} {:<34} {:<34} {:>6} {:>8} {:>10} {:>11}  {}\n",
        "model", "parameters", "excitation", "fs Hz", "samples", "R-RMSE %", "max |err|", "pass"
    );
    for r in rows {
        s += &format!(
            "{:<14} {:<34} {:<34} {:>6.0} {:>8} {:>10.4} {:>11.3e}  {}\n",
            r.model,
            trunc(&r.params, 34),
            trunc(&r.excitation, 34),
            r.fs_hz,
            r.samples,
            100.0 * r.r_rmse,
            r.max_abs_err,
            if r.pass { "yes" } else { "NO" }
        );
    }
    let worst = rows.iter().map(|r| r.r_rmse).fold(0.0, f64::max);
    let fails = rows.iter().filter(|r| !r.pass).count();
    s += &format!(
        "{} runs, worst R-RMSE {:.4} % (bound {:.1} %), {} over the bound\n",
        rows.len(),
        100.0 * worst,
        100.0 * MAX_R_RMSE,
        fails
    );
    s
}

fn trunc(s: &str, n: usize) -> String {
    if s.chars().count() <= n {
        s.to_owned()
    } else {
        s.chars().take(n - 1).chain(['…']).collect()
    }
}

pub fn run(a: AccuracyArgs) -> anyhow::Result<()> {
    let rows = rows(a.model.as_deref(), a.quick, a.no_recording)?;
    let fails = rows.iter().filter(|r| !r.pass).count();
    if a.json {
        let worst = rows.iter().map(|r| r.r_rmse).fold(0.0, f64::max);
        super::print_json(&json!({
            "bound_r_rmse": MAX_R_RMSE, "worst_r_rmse": worst, "failures": fails, "rows": rows,
        }))?;
    } else {
        super::emit(&table(&rows));
    }
    if fails > 0 {
        anyhow::bail!("{fails} accuracy run(s) exceed R-RMSE {:.1} %", 100.0 * MAX_R_RMSE);
    }
    Ok(())
}
