use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use hil_sim::io::params_file::ParamsFile;
use hil_sim::io::recording::Recording;
use hil_sim::models::replay::replay_recording;
use hil_sim::quality;
use serde_json::json;

use super::ChannelArgs;

#[derive(Args, Debug)]
pub struct ReplayArgs {
    /// Recording (CSV or level-5 MAT-file).
    pub rec: PathBuf,
    /// Parameter file (JSON: `{"model": ID, "params": {...}}`).
    #[arg(long)]
    pub params: PathBuf,
    #[command(flatten)]
    pub ch: ChannelArgs,
    /// Also write the trace as CSV: `t,measured,model,residual` (one row per sample).
    #[arg(long, value_name = "FILE")]
    pub trace: Option<PathBuf>,
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: ReplayArgs) -> anyhow::Result<()> {
    let pf = ParamsFile::read(&a.params)?;
    let rate = match (a.ch.rate()?, pf.rate.as_deref()) {
        (Some(r), _) => r,
        (None, Some(r)) => super::parse_rate(r).with_context(|| format!("{}: `rate`", a.params.display()))?,
        (None, None) => hil_sim::models::RateSpec::Backward,
    };
    let flat = pf.flat(&a.params)?;
    let rec = Recording::read(&super::file_arg(&a.rec)?)?;
    let q = quality::check(&rec, &a.ch.channels())?;
    for w in &q.warnings {
        eprintln!("warning: {}", w.message);
    }
    for n in &q.notes {
        eprintln!("warning: {n}");
    }
    if let Some(w) = super::constant_output(&a.ch.output, rec.channel(&a.ch.output)?) {
        eprintln!("warning: {w}");
    }
    let r = replay_recording(
        &rec,
        &a.ch.channels(),
        &pf.model,
        &flat,
        rate,
        (pf.delay_s.unwrap_or(0.0), pf.command_delay_s.unwrap_or(0.0)),
    )
    .with_context(|| format!("replaying {}", a.rec.display()))?;
    if let Some(path) = &a.trace {
        write_trace(path, &r).with_context(|| format!("writing trace {}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    if a.json {
        return super::print_json(&json!({
            "model": r.model, "samples": r.samples, "dt_s": r.dt_s,
            "metrics": r.metrics, "held": r.held,
            "warnings": q.warnings, "excluded_samples": q.excluded_samples,
        }));
    }
    let m = &r.metrics;
    super::emit(&format!(
        "{}: {} samples at {:.1} Hz through `{}` (f32, one step per sample)\n",
        a.rec.display(),
        r.samples,
        1.0 / r.dt_s,
        r.model
    ));
    super::emit(&format!(
        "  RMSE {:.4}  R-RMSE {:.2} %  R² {}  GOF {}  held samples {}\n",
        m.rmse,
        100.0 * m.r_rmse,
        super::fixed(m.r2, 4),
        super::fixed(m.gof, 4),
        r.held
    ));
    Ok(())
}

/// `t,measured,model,residual` with a header row.
fn write_trace(path: &std::path::Path, r: &hil_sim::models::replay::ReplayReport) -> anyhow::Result<()> {
    Ok(hil_sim::io::output::write_with(path, |out| {
        let mut w = csv::Writer::from_writer(out);
        w.write_record(["t", "measured", "model", "residual"])?;
        for ((t, y), m) in r.time.iter().zip(&r.measured).zip(&r.model_output) {
            w.write_record([t.to_string(), y.to_string(), m.to_string(), (y - m).to_string()])?;
        }
        w.flush()
    })?)
}
