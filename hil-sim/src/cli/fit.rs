use std::path::PathBuf;

use anyhow::bail;
use clap::Args;
use hil_sim::ident::fit::job::{self, FitJob};
use hil_sim::ident::fit::{Dataset, DelayChoice, FitOptions, FitResult};
use hil_sim::report::fit::Labels;
use hil_sim::report::fit_page;
use serde_json::json;

use super::{ChannelArgs, RecordingArgs};

#[derive(Args, Debug)]
pub struct FitArgs {
    #[command(flatten)]
    pub recs: RecordingArgs,
    /// Model id (see `hil-sim models`), a comma-separated list, or `all`.
    #[arg(long, default_value = "all")]
    pub model: String,
    /// Fraction of the recording (time-ordered, from the start) used for fitting; the rest
    /// is held out and scored.
    #[arg(long, default_value_t = 0.7)]
    pub train: f64,
    #[command(flatten)]
    pub ch: ChannelArgs,
    /// Channel alignment (physics-catalog `transport_delay`): `auto` fits an input delay, and
    /// a command delay when there is `--command`, with each model's parameters (±8 samples);
    /// `off` takes the channels as recorded; `D` or `D,DU` are known delays in seconds (the
    /// model is fed `x(t + D)` and `u(t + DU)`).
    #[arg(long, default_value = "auto", value_parser = parse_delay)]
    pub delay: DelayChoice,
    /// Seed of the global search (results are reproducible for a given seed).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Write each fitted set as `<DIR>/<model>.json` (a `replay --params` file).
    #[arg(long)]
    pub save: Option<PathBuf>,
    /// Write a report (report.md, index.html and SVG plots of the best model) to this folder.
    #[arg(long)]
    pub out: Option<PathBuf>,
    #[arg(long)]
    pub json: bool,
}

/// `auto`, `off` or seconds, the syntax of `--delay`.
pub fn parse_delay(s: &str) -> Result<DelayChoice, String> {
    match s {
        "auto" => Ok(DelayChoice::Auto),
        "off" | "0" => Ok(DelayChoice::Off),
        _ => {
            let bad = || format!("`{s}`: expected `auto`, `off`, or delays in seconds `D` or `D,DU`");
            let mut it = s.split(',').map(|v| v.trim().parse::<f64>().ok().filter(|v| v.is_finite()));
            let d = it.next().flatten().ok_or_else(bad)?;
            let d_u = it.next().map_or(Some(0.0), |v| v).ok_or_else(bad)?;
            if it.next().is_some() {
                return Err(bad());
            }
            Ok(DelayChoice::Fixed(d, d_u))
        }
    }
}

/// The models `--model` names.
pub fn model_list(arg: &str) -> anyhow::Result<Vec<String>> {
    if arg == "all" {
        return Ok(model_core::MODELS.iter().map(|m| m.id.to_owned()).collect());
    }
    let list: Vec<String> = arg.split(',').map(|s| s.trim().to_owned()).filter(|s| !s.is_empty()).collect();
    for id in &list {
        if model_core::registry::find(id).is_none() {
            bail!("--model {id}: unknown model (see `hil-sim models`)");
        }
    }
    if list.is_empty() {
        bail!("--model: no model named");
    }
    Ok(list)
}

/// Fit each model in `ids` on `data`, with a progress bar.
pub fn fit_all(data: &Dataset, ids: &[String], opts: &FitOptions) -> anyhow::Result<Vec<FitResult>> {
    let bar = super::progress::Bar::new(ids.len() as u64, "fitting");
    Ok(job::fit_many(data, ids, opts, &bar)?)
}

pub fn run(a: FitArgs) -> anyhow::Result<()> {
    let mut options = FitOptions { rate: a.ch.rate()?, delay: a.delay, ..Default::default() };
    options.swarm.seed = a.seed;
    let fit_job = FitJob {
        runs: a.recs.runs(&a.ch.channels())?,
        train: a.train,
        keep_flagged: a.ch.keep_flagged,
        models: model_list(&a.model)?,
        options,
        save: a.save.clone(),
    };
    let bar = super::progress::Bar::new(fit_job.models.len() as u64, "fitting");
    let run = job::run(&fit_job, &bar).map_err(|e| match &e {
        job::FitJobError::Dataset(d) if d.train_fraction().is_some() => {
            anyhow::anyhow!("--train {}: must be a fraction strictly between 0 and 1", a.train)
        }
        _ => e.into(),
    })?;
    bar.finish();
    let (label, data, q) = (a.recs.label(), &run.prepared.data, &run.prepared.quality);
    for r in run.each() {
        super::list_skipped(a.ch.verbose, &r.recording);
    }
    for w in &q.warnings {
        eprintln!("warning: {}", w.message);
    }
    for n in &q.notes {
        eprintln!("warning: {n}");
    }
    if let Some(w) = super::constant_output(&a.ch.output, &data.output) {
        eprintln!("warning: {w}");
    }
    for r in &run.results {
        for w in &r.warnings {
            eprintln!("warning: {}: {w}", r.model);
        }
    }
    if let Some(dir) = &a.out {
        let title = match a.recs.recs.as_slice() {
            [one] if a.recs.dataset.is_none() => format!("Fit of {}", hil_sim::report::file_label(one)),
            _ => format!("Fit of {label}"),
        };
        let labels = Labels::for_channels(&a.ch.input, &a.ch.output);
        // Messages name files without the user's folders.
        let paths: Vec<&std::path::Path> = run.each().iter().map(|r| r.recording.path.as_path()).collect();
        let warnings: Vec<String> = q
            .warnings
            .iter()
            .map(|w| w.message.clone())
            .chain(q.notes.iter().cloned())
            .map(|m| paths.iter().fold(m, |m, p| hil_sim::report::relabel(&m, p)))
            .collect();
        // One generation: the page and its plots swapped in together.
        let generation = hil_sim::io::output::generation::Generation::begin(dir)?;
        fit_page::write(generation.path(), &title, data, &run.results, &labels, &warnings)?;
        generation.commit("hil-sim fit --out")?;
        eprintln!("report written to {}", dir.join("index.html").display());
    }
    let best = run.best().map(|r| r.model.clone());
    // Samples in training parts (all of a dataset's runs; `train_end` for one recording).
    let train_samples: usize = data.spans().iter().map(|r| r.train_end - r.start).sum();
    if a.json {
        return super::print_json(&json!({
            "recording": label,
            "samples": data.len(),
            "dt_s": data.dt,
            "train_fraction": a.train,
            "train_samples": train_samples,
            "heldout_samples": data.len() - train_samples,
            "warnings": q.warnings,
            "notes": q.notes,
            "excluded_samples": if a.ch.keep_flagged { 0 } else { q.excluded_samples },
            "results": run.results,
            "best": best,
            "total_seconds": run.total_seconds,
        }));
    }
    if data.runs.is_empty() {
        super::emit(&format!(
            "{}: {} samples at {:.1} Hz; fit on the first {:.0} % ({} samples), scored on the last {} samples\n\n",
            label,
            data.len(),
            1.0 / data.dt,
            100.0 * a.train,
            data.train_end,
            data.len() - data.train_end
        ));
    } else {
        let validate = data.runs.iter().any(|r| r.role == hil_sim::io::manifest::Role::Validate);
        // Runs of one file are the stretches between gaps of its time column.
        let gaps = data.runs.windows(2).filter(|w| w[0].file == w[1].file).count();
        let split = match gaps {
            0 => String::new(),
            1 => " (one of them split at a gap in its time column)".to_owned(),
            k => format!(" (split at {k} gaps in the time columns)"),
        };
        super::emit(&format!(
            "{}: {} runs{split}, {} samples at {:.1} Hz (gaps left out of the rate); the model restarts at each run; {}\n\n",
            label,
            data.runs.len(),
            data.len(),
            1.0 / data.dt,
            if validate {
                "fit on the train runs, scored on the validate runs".to_owned()
            } else {
                format!("fit on the first {:.0} % of each run, scored on the rest", 100.0 * a.train)
            }
        ));
    }
    super::emit(&table(&run.results));
    if !data.runs.is_empty() {
        super::emit(&run_table(&run.results));
    }
    if let Some(b) = best {
        super::emit(&format!("\nbest held-out: {b}; total {:.2} s\n", run.total_seconds));
    }
    Ok(())
}

/// Each run's metrics, one row per model and run (pooled figures are in [`table`]).
pub fn run_table(results: &[FitResult]) -> String {
    let mut s = format!(
        "\nper run:\n{:<16} {:<32} {:<9} {:<8} {:>10} {:>9} {:>8}\n",
        "model", "run", "role", "scored", "RMSE", "R²", "R-RMSE"
    );
    for r in results {
        for run in &r.runs {
            let file =
                std::path::Path::new(&run.file).file_name().map_or(run.file.clone(), |f| f.to_string_lossy().into());
            s += &format!(
                "{:<16} {:<32} {:<9} {:<8} {:>10.4} {:>9} {:>7.2}%\n",
                r.model,
                file,
                run.role.label(),
                run.part,
                run.metrics.rmse,
                super::fixed(run.metrics.r2, 4),
                100.0 * run.metrics.r_rmse
            );
        }
    }
    s
}

/// The comparison table, one row per model.
pub fn table(results: &[FitResult]) -> String {
    let mut s = format!(
        "{:<16} {:>6} {:>10} {:>9} {:>8} {:>10} {:>9} {:>8} {:>8} {:>9} {:>13}\n",
        "model",
        "params",
        "train RMSE",
        "train R²",
        "method",
        "held RMSE",
        "held R²",
        "R-RMSE",
        "fit s",
        "ns/step",
        "delay x/u ms"
    );
    for r in results {
        s += &format!(
            "{:<16} {:>6} {:>10.4} {:>9} {:>8} {:>10.4} {:>9} {:>7.2}% {:>8.3} {:>9.1} {:>6.3}/{:<6.3}\n",
            r.model,
            r.free_params,
            r.train.rmse,
            super::fixed(r.train.r2, 4),
            format!("{:?}", r.method).to_lowercase(),
            r.heldout.rmse,
            super::fixed(r.heldout.r2, 4),
            100.0 * r.heldout.r_rmse,
            r.fit_seconds,
            r.replay_ns_per_sample,
            1e3 * r.delay_s,
            1e3 * r.command_delay_s
        );
    }
    s
}
