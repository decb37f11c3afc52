use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Args;
use hil_sim::ident::dataset::{Dataset, Keeping, Prepared};
use hil_sim::ident::diagnose::{diagnose, leak, DiagnoseError, DiagnoseOptions, Diagnosis};
use hil_sim::ident::runs::{prepare_runs, RunSpec, RunsError};
use hil_sim::io::recording::Channels;

use super::progress::Bar;
use super::{ChannelArgs, RecordingArgs};

#[derive(Args, Debug)]
pub struct DiagnoseArgs {
    #[command(flatten)]
    pub recs: RecordingArgs,
    /// Base model id, or `auto` (every seed model; the best held-out one is the base).
    #[arg(long, default_value = "auto")]
    pub model: String,
    /// Fraction of the recording held out (its end): the refits never see it.
    #[arg(long, default_value_t = 0.3)]
    pub heldout: f64,
    #[command(flatten)]
    pub ch: ChannelArgs,
    /// Most findings (rounds of naming and refitting).
    #[arg(long, default_value_t = 3)]
    pub max_findings: usize,
    /// Seed of the base model's global search.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Write a report (report.md, index.html and SVG plots) to this folder.
    #[arg(long)]
    pub out: Option<PathBuf>,
    #[arg(long)]
    pub json: bool,
}

/// The library's error with the flag that set the offending value.
fn flagged(e: DiagnoseError) -> anyhow::Error {
    match e {
        DiagnoseError::Heldout(v) => anyhow::anyhow!("--heldout {v}: must be between 0.05 and 0.8"),
        e => e.into(),
    }
}

/// Read, check and diagnose the recording at `rec` (channels `ch`; samples the quality
/// check flags left out unless `keep_flagged`); shared with the demo.
pub fn run_diagnosis(
    rec: &Path,
    ch: &Channels,
    keep_flagged: bool,
    opts: &DiagnoseOptions,
) -> anyhow::Result<(Diagnosis, Dataset)> {
    let run = RunSpec { path: super::file_arg(rec)?, channels: ch.clone(), role: hil_sim::io::manifest::Role::Train };
    run_diagnosis_runs(&[run], keep_flagged, opts)
}

/// [`run_diagnosis`] of a dataset: the runs joined with their boundaries kept
/// ([`Dataset::run_starts`]), the auxiliary channels every run has joined the same way.
pub fn run_diagnosis_runs(
    runs: &[RunSpec],
    keep_flagged: bool,
    opts: &DiagnoseOptions,
) -> anyhow::Result<(Diagnosis, Dataset)> {
    opts.check().map_err(flagged)?;
    let Some(first) = runs.first() else { anyhow::bail!("no recording given") };
    let (path, ch) = (&first.path, &first.channels);
    let prepared = prepare_runs(runs, 1.0 - opts.heldout, keep_flagged, Keeping::Everything).map_err(|e| match e {
        RunsError::Dataset(d) => anyhow::Error::from(d),
        e => e.into(),
    })?;
    let aux = joined_auxiliary(prepared.each(), runs);
    let Prepared { quality: q, data, .. } = prepared.joined;
    for w in &q.warnings {
        eprintln!("warning: {}", w.message);
    }
    for n in &q.notes {
        eprintln!("warning: {n}");
    }
    let (aux, dropped) = leak::screen(aux, &data.output, ch.command.as_deref());
    for d in &dropped {
        eprintln!("warning: {}: channel `{}` is not used by the diagnosis: {}", path.display(), d.name, d.reason);
    }
    let bar = Bar::new(1, "diagnosing");
    let d = diagnose(&data, aux, ch.command.as_deref(), (&ch.input, &ch.output), opts, &bar);
    bar.finish();
    let d = d.map_err(flagged).with_context(|| format!("diagnosing {}", path.display()))?;
    Ok((d, data))
}

/// The auxiliary channels of every run, joined end to end (a channel some run lacks is left out).
fn joined_auxiliary(prepared: &[Prepared], runs: &[RunSpec]) -> Vec<(String, Vec<f64>)> {
    let per_run: Vec<Vec<(String, Vec<f64>)>> =
        prepared.iter().zip(runs).map(|(p, r)| p.recording.auxiliary_channels(&r.channels)).collect();
    let Some(first) = per_run.first() else { return Vec::new() };
    first
        .iter()
        .filter_map(|(name, _)| {
            let mut v = Vec::new();
            for run in &per_run {
                v.extend_from_slice(&run.iter().find(|(n, _)| n == name)?.1);
            }
            Some((name.clone(), v))
        })
        .collect()
}

pub fn run(a: DiagnoseArgs) -> anyhow::Result<()> {
    let opts = DiagnoseOptions {
        model: (a.model != "auto").then(|| a.model.clone()),
        heldout: a.heldout,
        rate: None,
        seed: a.seed,
        max_findings: a.max_findings,
        ..DiagnoseOptions::default()
    };
    opts.check().map_err(flagged)?;
    if let Some(m) = &opts.model {
        super::fit::model_list(m)?;
        if m.contains(',') {
            anyhow::bail!("--model {m}: one base model (or `auto`)");
        }
    }
    let opts = DiagnoseOptions { rate: a.ch.rate()?, ..opts };
    let runs = a.recs.runs(&a.ch.channels())?;
    let (d, _) = run_diagnosis_runs(&runs, a.ch.keep_flagged, &opts)?;
    if let Some(dir) = &a.out {
        // One generation: the page and its plots swapped in together.
        let generation = hil_sim::io::output::generation::Generation::begin(dir)?;
        let stage = generation.path().to_path_buf();
        let label = match a.recs.recs.as_slice() {
            [one] if a.recs.dataset.is_none() => hil_sim::report::file_label(one),
            _ => a.recs.label(),
        };
        let mut rep = hil_sim::report::Report::new(format!("Diagnosis of {label}"));
        hil_sim::report::diagnose::section(&mut rep, &stage, "diagnose", &d, (&a.ch.input, &a.ch.output))?;
        rep.write(&stage)?;
        generation.commit("hil-sim diagnose --out")?;
        eprintln!("report written to {}", dir.join("index.html").display());
    }
    if a.json {
        return super::print_json(&serde_json::to_value(&d)?);
    }
    super::emit(&text(&d));
    Ok(())
}

/// The diagnosis in words.
pub fn text(d: &Diagnosis) -> String {
    let unit = if d.units.1.is_empty() { "(output units)" } else { d.units.1.as_str() };
    let b = &d.base_heldout;
    // The fit alone and the reference the candidates were judged against, when they differ.
    let reference = d.reference_apart().map_or_else(String::new, |r| {
        format!(
            "; refitted until it stalls (the reference every candidate is judged against) {:.2} %, R² {:.4}",
            100.0 * r.r_rmse,
            r.r2
        )
    });
    let mut s = format!(
        "base model {}: held-out R-RMSE {:.2} %, R² {:.4} as fitted{reference} (residual noise floor {} RMS)\n",
        d.base_model,
        100.0 * b.r_rmse,
        b.r2,
        hil_sim::numerics::number::with_unit(d.locate.noise_rms, 4, unit)
    );
    for n in &d.notes {
        s += &format!("note: {n}\n");
    }
    if d.findings.is_empty() {
        s += "no finding: nothing in the catalog lowers the held-out error by more than chance\n";
    }
    for (k, f) in d.findings.iter().enumerate() {
        s += &format!("{}. {}: {}\n", k + 1, f.effect, f.summary);
        if !f.windows.is_empty() {
            let w: Vec<String> = f.windows.iter().map(|(a, b)| format!("{a:.2}-{b:.2} s")).collect();
            s += &format!("   where: {}", w.join(", "));
            if let Some(c) = f.conditions.first() {
                s += &format!("; mostly at {} {} ({:.1}× its share of samples)", c.variable, c.bin, c.concentration);
            }
            s += "\n";
        }
    }
    s += &format!(
        "final: held-out R-RMSE {:.2} %, R² {:.4}; {:.1} s\n",
        100.0 * d.final_heldout.r_rmse,
        d.final_heldout.r2,
        d.seconds
    );
    s
}
