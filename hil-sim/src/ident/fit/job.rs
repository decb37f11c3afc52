//! `fit` as one call: read and check a recording, fit every named model with progress,
//! save each fitted set as a parameter file.

use std::path::{Path, PathBuf};
use std::time::Instant;

use std::sync::Mutex;
use thiserror::Error;

use super::{fit, FitError, FitOptions, FitResult};
use crate::ident::dataset::{DatasetError, Keeping, Prepared};
use crate::ident::runs::{prepare_runs, RunSpec, RunsError};
use crate::io::output::generation::Generation;
use crate::io::params_file::{FittedChannels, ParamsFile};
use crate::progress::Progress;

/// What to fit, on what.
#[derive(Clone, Debug)]
pub struct FitJob {
    /// The recordings, each with its channels and role: one, or the runs of a dataset.
    pub runs: Vec<RunSpec>,
    /// Fraction of each recording (time-ordered, from the start) fitted; the rest is scored
    /// (unless the dataset has `validate` runs).
    pub train: f64,
    /// Keep the samples the quality checks flag in the fit.
    pub keep_flagged: bool,
    pub models: Vec<String>,
    pub options: FitOptions,
    /// Write each fitted set as `<dir>/<model>.json`, and the metrics as [`RESULTS_FILE`].
    pub save: Option<PathBuf>,
}

/// The outcome of a [`FitJob`].
#[derive(Clone, Debug)]
pub struct FitRun {
    /// The data fitted (a dataset's runs joined, [`crate::ident::dataset::Dataset::runs`]).
    pub prepared: Prepared,
    /// Each recording's own preparation when there are several (empty for a single
    /// recording, which is `prepared`); [`FitRun::each`] gives both cases.
    pub runs: Vec<Prepared>,
    /// One per model, in the job's order.
    pub results: Vec<FitResult>,
    /// Files written: the parameter files, then [`RESULTS_FILE`].
    pub saved: Vec<PathBuf>,
    /// Wall time of the fits, seconds.
    pub total_seconds: f64,
}

impl FitRun {
    /// Each recording's preparation (the one recording's for a single run).
    pub fn each(&self) -> &[Prepared] {
        match self.runs.as_slice() {
            [] => std::slice::from_ref(&self.prepared),
            runs => runs,
        }
    }

    /// The model with the lowest held-out RMSE.
    pub fn best(&self) -> Option<&FitResult> {
        self.results
            .iter()
            .filter(|r| r.heldout.rmse.is_finite())
            .min_by(|x, y| x.heldout.rmse.total_cmp(&y.heldout.rmse))
    }
}

/// Why a fit job stopped.
#[derive(Debug, Error)]
pub enum FitJobError {
    #[error(transparent)]
    Dataset(#[from] DatasetError),
    #[error(transparent)]
    Runs(RunsError),
    #[error("fitting `{model}`")]
    Fit { model: String, source: Box<FitError> },
    #[error("{}: {reason}", path.display())]
    Save { path: PathBuf, reason: String },
    #[error(transparent)]
    Generation(#[from] crate::io::output::generation::GenerationError),
}

/// Fit each model in `ids` on `data`, one progress step per model; results in the order of `ids`.
/// The models are fitted side by side (each fit is deterministic on its own, so the results
/// are those of fitting them one after another), the longest searches started first so that
/// no long fit is left to run alone at the end; the first error in the order of `ids` is
/// returned.
pub fn fit_many(
    data: &crate::ident::dataset::Dataset,
    ids: &[String],
    opts: &FitOptions,
    progress: &dyn Progress,
) -> Result<Vec<FitResult>, FitJobError> {
    progress.stage("fitting", ids.len() as u64);
    let mut order: Vec<usize> = (0..ids.len()).collect();
    let scales = data.scales();
    order.sort_by_key(|&i| expected_cost(&ids[i], &scales, opts));
    let slots: Vec<Mutex<Option<Result<FitResult, FitJobError>>>> = ids.iter().map(|_| Mutex::new(None)).collect();
    // FIFO: the workers take the fits in `order`, each the next one when it is free.
    rayon::scope_fifo(|s| {
        for &i in &order {
            let (Some(id), Some(slot)) = (ids.get(i), slots.get(i)) else { continue };
            s.spawn_fifo(move |_| {
                progress.message(id);
                let r = fit(id, data, opts)
                    .map_err(|source| FitJobError::Fit { model: id.clone(), source: Box::new(source) });
                progress.advance(1);
                if let Ok(mut slot) = slot.lock() {
                    *slot = Some(r);
                }
            });
        }
    });
    slots
        .into_iter()
        .zip(ids)
        .map(|(slot, id)| {
            slot.into_inner().ok().flatten().unwrap_or_else(|| {
                Err(FitJobError::Fit { model: id.clone(), source: Box::new(FitError::UnknownModel(id.clone())) })
            })
        })
        .collect()
}

/// Rank of model `id`'s fit by its usual cost, longest first: the networks, the projected
/// operator models, the global searches (more free parameters first), then the rest.
fn expected_cost(
    id: &str,
    scales: &crate::models::search::Scales,
    opts: &FitOptions,
) -> (u8, std::cmp::Reverse<usize>) {
    use crate::models::search::Strategy;
    let Some(sp) = crate::models::host(id).and_then(|h| h.spec(scales, opts.rate)) else {
        return (u8::MAX, std::cmp::Reverse(0));
    };
    let rank = match sp.strategy {
        Strategy::Network => 0,
        Strategy::Projected => 1,
        Strategy::Global => 2,
        Strategy::Local => 3,
        Strategy::Operator => 4,
        Strategy::Linear => 5,
    };
    (rank, std::cmp::Reverse(sp.free().len()))
}

/// Run the job: prepare the recording, fit, save.
pub fn run(job: &FitJob, progress: &dyn Progress) -> Result<FitRun, FitJobError> {
    let prepared = prepare_runs(&job.runs, job.train, job.keep_flagged, Keeping::DatasetOnly).map_err(|e| match e {
        RunsError::Dataset(d) => FitJobError::Dataset(d),
        e => FitJobError::Runs(e),
    })?;
    let t0 = Instant::now();
    let results = fit_many(&prepared.joined.data, &job.models, &job.options, progress)?;
    let total_seconds = t0.elapsed().as_secs_f64();
    let saved = match (&job.save, job.runs.first()) {
        (Some(dir), Some(first)) => {
            let files: Vec<&Path> = job.runs.iter().map(|r| r.path.as_path()).collect();
            save(dir, &results, &files, &FittedChannels::of(&first.channels))?
        }
        _ => Vec::new(),
    };
    Ok(FitRun { prepared: prepared.joined, runs: prepared.runs, results, saved, total_seconds })
}

/// Write each result as `<dir>/<model>.json`, a `replay --params` file naming its source
/// recordings and the channels it was fitted on.
pub fn save(
    dir: &Path,
    results: &[FitResult],
    recordings: &[&Path],
    channels: &FittedChannels,
) -> Result<Vec<PathBuf>, FitJobError> {
    let err = |path: &Path, reason: String| FitJobError::Save { path: path.to_owned(), reason };
    // One generation: every file of this save, swapped in together, or none of them.
    let generation = Generation::begin(dir)?;
    let stage = generation.path().to_path_buf();
    let mut written = Vec::with_capacity(results.len() + 1);
    let source = format!("hil-sim fit {}", source_label(recordings));
    for r in results {
        let name = format!("{}.json", r.model);
        let file = stage.join(&name);
        let flat: Vec<f32> = r.flat.iter().map(|v| *v as f32).collect();
        let mut pf = ParamsFile::from_flat(&r.model, Some(source.clone()), &flat)
            .ok_or_else(|| err(&file, "cannot build the parameter file".into()))?;
        pf.channels = Some(channels.clone());
        pf.rate = Some(r.rate.clone());
        pf.delay_s = (r.delay_s != 0.0).then_some(r.delay_s);
        pf.command_delay_s = (r.command_delay_s != 0.0).then_some(r.command_delay_s);
        let text = serde_json::to_string_pretty(&pf).map_err(|e| err(&file, e.to_string()))? + "\n";
        // What `replay` and `export` read, `fit` writes: never a file they would refuse.
        if text.len() as u64 > crate::io::params_file::MAX_BYTES {
            return Err(err(&file, format!("{} bytes, over the parameter file limit", text.len())));
        }
        crate::io::output::write(&file, text).map_err(|e| err(&dir.join(&name), e.to_string()))?;
        written.push(dir.join(name));
    }
    // The scores, per model and per run, beside the sets: as large as the dataset is, so
    // never inside a parameter file.
    let file = dir.join(RESULTS_FILE);
    let text = serde_json::to_string_pretty(&serde_json::json!({ "source": source, "results": results }))
        .map_err(|e| err(&file, e.to_string()))?
        + "\n";
    crate::io::output::write(&stage.join(RESULTS_FILE), text).map_err(|e| err(&file, e.to_string()))?;
    written.push(file);
    generation.commit(&source)?;
    Ok(written)
}

/// The file `fit --save DIR` writes beside the parameter files: every model's metrics,
/// pooled and per run.
pub const RESULTS_FILE: &str = "fit-results.json";

/// The recordings a set was fitted on, as its `source` names them: all of them when they
/// are few, else how many with the first and the last (a dataset of thousands of runs would
/// make a parameter file of megabytes).
fn source_label(recordings: &[&Path]) -> String {
    const LISTED: usize = 4;
    let names: Vec<String> = recordings.iter().map(|p| p.display().to_string()).collect();
    match names.as_slice() {
        [first, .., last] if names.len() > LISTED => format!("{} recordings: {first} … {last}", names.len()),
        _ => names.join(" "),
    }
}
