use std::path::PathBuf;

use anyhow::{bail, Context};
use clap::Args;
use hil_sim::io::params_file::ParamsFile;
use hil_sim::io::recording::{Channels, Keep, Recording};
use hil_sim::models::replay::{pooled, replay_recording, ReplayReport};
use hil_sim::quality;
use serde_json::json;

use super::{ChannelArgs, RecordingArgs};

#[derive(Args, Debug)]
pub struct ReplayArgs {
    #[command(flatten)]
    pub recs: RecordingArgs,
    /// Parameter file (JSON: `{"model": ID, "params": {...}}`). The channels it was fitted
    /// on (`fit --save` records them) are used unless the flags name others.
    #[arg(long)]
    pub params: PathBuf,
    #[command(flatten)]
    pub ch: ChannelArgs,
    /// Also write the trace as CSV: `t,measured,model,residual` (one row per sample; the
    /// first recording's).
    #[arg(long, value_name = "FILE")]
    pub trace: Option<PathBuf>,
    #[arg(long)]
    pub json: bool,
}

/// The channels to replay with: a flag left at its default gives way to the channel the
/// parameter file was fitted on; without `--command`, the file's command channel is used.
fn channels(a: &ReplayArgs, pf: &ParamsFile) -> Channels {
    let mut ch = a.ch.channels();
    let Some(f) = &pf.channels else { return ch };
    let d = Channels::default();
    if ch.time == d.time {
        ch.time.clone_from(&f.time);
    }
    if ch.input == d.input {
        ch.input.clone_from(&f.input);
    }
    if ch.output == d.output {
        ch.output.clone_from(&f.output);
    }
    if ch.command.is_none() {
        ch.command.clone_from(&f.command);
    }
    ch
}

/// One recording through the model.
fn one(
    rec: Recording,
    ch: &Channels,
    pf: &ParamsFile,
    flat: &[f32],
    a: &ReplayArgs,
    rate: hil_sim::models::RateSpec,
) -> anyhow::Result<(ReplayReport, quality::Quality)> {
    let mut rec = rec;
    super::list_skipped(a.ch.verbose, &rec);
    rec.apply_constants(ch)?;
    if let (Some(f), Some(cmd)) = (&pf.channels, ch.command.as_deref()) {
        if rec.channel(cmd).is_err() && f.command.as_deref() == Some(cmd) {
            bail!(
                "{}: `{}` was fitted with the command channel `{cmd}`, which this recording lacks; \
                 name it with --command NAME or give a constant with --set {cmd}=VALUE",
                rec.path.display(),
                a.params.display()
            );
        }
    }
    let q = quality::check(&rec, ch)?;
    for w in &q.warnings {
        eprintln!("warning: {}", w.message);
    }
    for n in &q.notes {
        eprintln!("warning: {n}");
    }
    if let Some(w) = super::constant_output(&ch.output, rec.channel(&ch.output)?) {
        eprintln!("warning: {w}");
    }
    let delays = (pf.delay_s.unwrap_or(0.0), pf.command_delay_s.unwrap_or(0.0));
    let path = rec.path.clone();
    let r = replay_recording(rec, ch, &pf.model, flat, rate, delays)
        .with_context(|| format!("replaying {}", path.display()))?;
    Ok((r, q))
}

pub fn run(a: ReplayArgs) -> anyhow::Result<()> {
    let pf = ParamsFile::read(&a.params)?;
    let rate = match (a.ch.rate()?, pf.rate.as_deref()) {
        (Some(r), _) => r,
        (None, Some(r)) => super::parse_rate(r).with_context(|| format!("{}: `rate`", a.params.display()))?,
        (None, None) => hil_sim::models::RateSpec::Backward,
    };
    let flat = pf.flat(&a.params)?;
    let ch = channels(&a, &pf);
    if let (Some(f), None) = (&pf.channels, &ch.command) {
        if let Some(c) = &f.command {
            eprintln!("warning: `{}` was fitted with the command channel `{c}`", a.params.display());
        }
    }
    let specs = a.recs.runs(&ch)?;
    let mut reports = Vec::with_capacity(specs.len());
    let mut qualities = Vec::with_capacity(specs.len());
    for s in &specs {
        let rec = Recording::read_keeping(&s.path, &Keep::roles(&s.channels))?;
        let (r, q) = one(rec, &s.channels, &pf, &flat, &a, rate)?;
        reports.push(r);
        qualities.push(q);
    }
    let Some(first) = reports.first() else { bail!("no recording given") };
    if let Some(path) = &a.trace {
        write_trace(path, first).with_context(|| format!("writing trace {}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    if let [r] = reports.as_slice() {
        return print_one(&a, r, &qualities[0], &specs[0].path);
    }
    let metrics = pooled(&reports)?;
    if a.json {
        let runs: Vec<_> = specs
            .iter()
            .zip(&reports)
            .map(|(s, r)| json!({"file": s.path.display().to_string(), "role": s.role, "metrics": r.metrics, "samples": r.samples, "held": r.held}))
            .collect();
        return super::print_json(&json!({
            "model": pf.model, "samples": reports.iter().map(|r| r.samples).sum::<usize>(),
            "dt_s": first.dt_s, "metrics": metrics, "held": reports.iter().map(|r| r.held).sum::<usize>(),
            "runs": runs,
        }));
    }
    for (s, r) in specs.iter().zip(&reports) {
        super::emit(&format!("{} ({}): {}", s.path.display(), s.role.label(), line(&r.metrics, r.held)));
    }
    super::emit(&format!(
        "pooled over {} runs: {}",
        reports.len(),
        line(&metrics, reports.iter().map(|r| r.held).sum())
    ));
    Ok(())
}

fn line(m: &hil_sim::numerics::metrics::Metrics, held: usize) -> String {
    format!(
        "RMSE {:.4}  R-RMSE {:.2} %  R² {}  GOF {}  held samples {}\n",
        m.rmse,
        100.0 * m.r_rmse,
        super::fixed(m.r2, 4),
        super::fixed(m.gof, 4),
        held
    )
}

fn print_one(a: &ReplayArgs, r: &ReplayReport, q: &quality::Quality, path: &std::path::Path) -> anyhow::Result<()> {
    if a.json {
        return super::print_json(&json!({
            "model": r.model, "samples": r.samples, "dt_s": r.dt_s,
            "metrics": r.metrics, "held": r.held,
            "warnings": q.warnings, "excluded_samples": q.excluded_samples,
        }));
    }
    super::emit(&format!(
        "{}: {} samples at {:.1} Hz through `{}` (f32, one step per sample)\n",
        path.display(),
        r.samples,
        1.0 / r.dt_s,
        r.model
    ));
    super::emit(&format!("  {}", line(&r.metrics, r.held)));
    Ok(())
}

/// `t,measured,model,residual` with a header row.
fn write_trace(path: &std::path::Path, r: &ReplayReport) -> anyhow::Result<()> {
    Ok(hil_sim::io::output::write_with(path, |out| {
        let mut w = csv::Writer::from_writer(out);
        w.write_record(["t", "measured", "model", "residual"])?;
        for ((t, y), m) in r.time.iter().zip(&r.measured).zip(&r.model_output) {
            w.write_record([t.to_string(), y.to_string(), m.to_string(), (y - m).to_string()])?;
        }
        w.flush()
    })?)
}
