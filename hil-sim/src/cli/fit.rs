use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Context};
use clap::Args;
use hil_sim::fit::spec::FITTABLE;
use hil_sim::fit::{fit, Dataset, DelayChoice, FitOptions, FitResult};
use hil_sim::params_file::ParamsFile;
use hil_sim::quality;
use hil_sim::recording::Recording;
use serde_json::json;

use super::ChannelArgs;

#[derive(Args, Debug)]
pub struct FitArgs {
    /// Recording (CSV).
    pub rec: PathBuf,
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
        return Ok(FITTABLE.iter().map(|s| (*s).to_owned()).collect());
    }
    let list: Vec<String> = arg.split(',').map(|s| s.trim().to_owned()).filter(|s| !s.is_empty()).collect();
    for id in &list {
        if model_core::registry::find(id).is_none() {
            bail!("--model {id}: unknown model (see `hil-sim models`)");
        }
        if !FITTABLE.contains(&id.as_str()) {
            bail!("--model {id}: not fitted by this build (fittable: {})", FITTABLE.join(", "));
        }
    }
    if list.is_empty() {
        bail!("--model: no model named");
    }
    Ok(list)
}

/// Fit each model in `ids`, with a progress bar; results in the order of `ids`.
pub fn fit_all(data: &Dataset, ids: &[String], opts: &FitOptions) -> anyhow::Result<Vec<FitResult>> {
    let pb = super::progress(ids.len() as u64, "fitting");
    // Models run one after another; each fit is parallel inside (swarm, Jacobian columns).
    let mut out = Vec::with_capacity(ids.len());
    for id in ids {
        pb.set_message(id.clone());
        let r = fit(id, data, opts).with_context(|| format!("fitting `{id}`"))?;
        pb.inc(1);
        out.push(r);
    }
    pb.finish_and_clear();
    Ok(out)
}

pub fn run(a: FitArgs) -> anyhow::Result<()> {
    let ids = model_list(&a.model)?;
    let rate = a.ch.rate()?;
    let path = super::file_arg(&a.rec)?;
    let rec = Recording::read(&path)?;
    let ch = a.ch.channels();
    let q = quality::check(&rec, &ch)?;
    for w in &q.warnings {
        eprintln!("warning: {}", w.message);
    }
    let excluded = (!a.ch.keep_flagged).then(|| q.excluded());
    let data = Dataset::new(&rec, &ch, a.train, excluded).with_context(|| format!("{}", path.display()))?;
    let mut opts = FitOptions { rate, delay: a.delay, ..Default::default() };
    opts.swarm.seed = a.seed;
    let t0 = Instant::now();
    let results = fit_all(&data, &ids, &opts)?;
    let total = t0.elapsed().as_secs_f64();
    for r in &results {
        for w in &r.warnings {
            eprintln!("warning: {}: {w}", r.model);
        }
    }
    if let Some(dir) = &a.save {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        for r in &results {
            let flat: Vec<f32> = r.flat.iter().map(|v| *v as f32).collect();
            let mut pf = ParamsFile::from_flat(&r.model, Some(format!("hil-sim fit {}", path.display())), &flat)
                .context("building the parameter file")?;
            pf.rate = Some(r.rate.clone());
            pf.delay_s = (r.delay_s != 0.0).then_some(r.delay_s);
            pf.command_delay_s = (r.command_delay_s != 0.0).then_some(r.command_delay_s);
            let file = dir.join(format!("{}.json", r.model));
            std::fs::write(&file, serde_json::to_string_pretty(&pf)? + "\n")
                .with_context(|| format!("writing {}", file.display()))?;
        }
    }
    let best = results
        .iter()
        .filter(|r| r.heldout.rmse.is_finite())
        .min_by(|x, y| x.heldout.rmse.total_cmp(&y.heldout.rmse))
        .map(|r| r.model.clone());
    if let Some(dir) = &a.out {
        let title = format!("Fit of {}", path.display());
        let index = write_report(dir, &title, &data, &results, &a.ch.input, &a.ch.output)?;
        eprintln!("report written to {}", index.display());
    }
    if a.json {
        return super::print_json(&json!({
            "recording": path.display().to_string(),
            "samples": data.len(),
            "dt_s": data.dt,
            "train_fraction": a.train,
            "train_samples": data.train_end,
            "heldout_samples": data.len() - data.train_end,
            "warnings": q.warnings,
            "excluded_samples": if a.ch.keep_flagged { 0 } else { q.excluded_samples },
            "results": results,
            "best": best,
            "total_seconds": total,
        }));
    }
    super::emit(&format!(
        "{}: {} samples at {:.1} Hz; fit on the first {:.0} % ({} samples), scored on the last {} samples\n\n",
        path.display(),
        data.len(),
        1.0 / data.dt,
        100.0 * a.train,
        data.train_end,
        data.len() - data.train_end
    ));
    super::emit(&table(&results));
    if let Some(b) = best {
        super::emit(&format!("\nbest held-out: {b}; total {total:.2} s\n"));
    }
    Ok(())
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
            "{:<16} {:>6} {:>10.4} {:>9.4} {:>8} {:>10.4} {:>9.4} {:>7.2}% {:>8.3} {:>9.1} {:>6.3}/{:<6.3}\n",
            r.model,
            r.free_params,
            r.train.rmse,
            r.train.r2,
            format!("{:?}", r.method).to_lowercase(),
            r.heldout.rmse,
            r.heldout.r2,
            100.0 * r.heldout.r_rmse,
            r.fit_seconds,
            r.replay_ns_per_sample,
            1e3 * r.delay_s,
            1e3 * r.command_delay_s
        );
    }
    s
}

/// Write a fit report: the table, the error bars, and the plots of the best model (by
/// held-out RMSE). Returns the path of `index.html`.
pub fn write_report(
    dir: &std::path::Path,
    title: &str,
    data: &Dataset,
    results: &[FitResult],
    input: &str,
    output: &str,
) -> anyhow::Result<PathBuf> {
    use hil_sim::report::fit::{error_bars, fit_plots, loop_plots, results_table, Labels};
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let mut rep = hil_sim::report::Report::new(title);
    rep.paragraph(&format!(
        "{} samples at {:.1} Hz; fitted on the first {} samples, scored on the last {}. Metrics are from the \
         f32 replay through model-core (the firmware's code), one step per sample.",
        data.len(),
        1.0 / data.dt,
        data.train_end,
        data.len() - data.train_end
    ));
    results_table(&mut rep, results);
    let stem = |m: &str| format!("fit_{m}");
    error_bars(&mut rep, dir, "fit", results)?;
    let labels = Labels { input: input.to_owned(), output: output.to_owned() };
    if let Some(best) = results.iter().min_by(|x, y| x.heldout.rmse.total_cmp(&y.heldout.rmse)) {
        rep.heading(&format!("Best held-out model: {}", best.model));
        fit_plots(&mut rep, dir, &stem(&best.model), data, best, &labels)?;
    }
    for r in results.iter().filter(|r| !r.warnings.is_empty()) {
        for w in &r.warnings {
            rep.paragraph(&format!("**Warning ({}):** {w}", r.model));
        }
    }
    rep.heading("Hysteresis loops of every model (held-out part)");
    loop_plots(&mut rep, dir, "heldout", data, results, &labels)?;
    Ok(rep.write(dir)?)
}
