//! The data an identification works on: a recording's input, output and command channels,
//! split in time into a training and a held-out part, with the samples the quality checks
//! flagged ([`prepare`] reads, checks and splits in one call).

use std::path::{Path, PathBuf};

use model_core::Sample;
use thiserror::Error;

use crate::io::recording::Channels;
use crate::io::recording::{Keep, Recording, RecordingError};
use crate::models::search::Scales;
use crate::numerics::derivative::gradient;
use crate::numerics::stats::mean_std_at;
use crate::quality::{self, Quality};

/// Why a dataset could not be built.
#[derive(Debug, Error)]
pub enum DatasetError {
    #[error(transparent)]
    Recording(#[from] RecordingError),
    #[error(transparent)]
    TimeUnit(#[from] quality::timing::TimeUnitError),
    #[error("the input `{channel}` is constant ({value}) over the whole recording: nothing to identify")]
    ConstantInput { channel: String, value: f64 },
    #[error("training fraction {0}: must be strictly between 0 and 1")]
    TrainFraction(f64),
    #[error("the training part has only {0} usable samples (need at least 20)")]
    TooFewSamples(usize),
    #[error("the held-out part is empty (use a smaller training fraction)")]
    NoHeldOut,
    #[error("{}: {inner}", path.display())]
    In { path: PathBuf, inner: Box<DatasetError> },
}

/// The data a fit works on.
#[derive(Clone, Debug)]
pub struct Dataset {
    /// Mean sample interval, seconds: the core's fixed step.
    pub dt: f64,
    pub time: Vec<f64>,
    pub input: Vec<f64>,
    pub output: Vec<f64>,
    pub command: Option<Vec<f64>>,
    /// First held-out sample.
    pub train_end: usize,
    /// Samples the quality checks flagged: excluded from the fit (the model still runs
    /// through them) and scored separately.
    pub excluded: Vec<bool>,
    /// Samples no score may include (gross outliers, [`crate::quality::Quality::unusable`]).
    pub unusable: Vec<usize>,
    /// Given rate and acceleration of the input (e.g. [`crate::numerics::derivative::rates`]): fed to
    /// the models instead of the rate estimator's when present.
    pub rates: Option<(Vec<f64>, Vec<f64>)>,
    /// The runs of a dataset joined end to end ([`crate::ident::runs`]): the model restarts at
    /// each run's start and each has its own split. Empty: one run, split at `train_end`.
    pub runs: Vec<RunSpan>,
}

/// One run of a dataset: samples `start..end` of the joined data, `start..train_end` fitted.
#[derive(Clone, Debug, PartialEq)]
pub struct RunSpan {
    pub file: PathBuf,
    pub role: crate::io::manifest::Role,
    pub start: usize,
    pub train_end: usize,
    pub end: usize,
}

impl Dataset {
    /// Take the channels `ch` of `rec` and split at `train` (fraction of the samples, time-ordered).
    /// `excluded` marks flagged samples (`None`: none).
    pub fn new(rec: &Recording, ch: &Channels, train: f64, excluded: Option<Vec<bool>>) -> Result<Self, DatasetError> {
        if !(train > 0.0 && train < 1.0) {
            return Err(DatasetError::TrainFraction(train));
        }
        rec.check_roles(ch)?;
        let time = rec.time(&ch.time)?.to_vec();
        let input = rec.channel(&ch.input)?.to_vec();
        let output = rec.channel(&ch.output)?.to_vec();
        let command = ch.command.as_deref().map(|c| rec.channel(c).map(<[f64]>::to_vec)).transpose()?;
        quality::timing::check_time_unit(&ch.time, &time)?;
        if let Some(v) = input.first().filter(|v| input.iter().all(|x| x == *v)) {
            return Err(DatasetError::ConstantInput { channel: ch.input.clone(), value: *v });
        }
        let dt = rec.sample_interval(&ch.time)?;
        let n = input.len();
        let train_end = ((n as f64) * train).round() as usize;
        if train_end >= n {
            return Err(DatasetError::NoHeldOut);
        }
        let excluded = excluded.filter(|e| e.len() == n).unwrap_or_else(|| vec![false; n]);
        let runs = gap_runs(&rec.path, &time, dt, train);
        let mut d =
            Self { dt, time, input, output, command, train_end, excluded, unusable: Vec::new(), rates: None, runs };
        if let Some(last) = d.runs.last() {
            d.train_end = last.train_end;
        }
        let usable = d.train_rows().len();
        if usable < 20 {
            return Err(DatasetError::TooFewSamples(usable));
        }
        Ok(d)
    }

    pub fn len(&self) -> usize {
        self.input.len()
    }
    pub fn is_empty(&self) -> bool {
        self.input.is_empty()
    }

    /// The samples as the core sees them (f32, with the command when there is one, and the
    /// given rates when there are some).
    pub fn samples(&self) -> Vec<Sample> {
        crate::models::replay::samples_with_rates(&self.input, self.command.as_deref(), self.rates.as_ref())
    }

    /// The runs (one spanning everything, split at `train_end`, for a single recording).
    pub fn spans(&self) -> Vec<RunSpan> {
        if self.runs.is_empty() {
            vec![RunSpan {
                file: PathBuf::new(),
                role: crate::io::manifest::Role::Train,
                start: 0,
                train_end: self.train_end,
                end: self.len(),
            }]
        } else {
            self.runs.clone()
        }
    }

    /// Where each run starts (sample indices; `[0]` for a single recording): the model's state,
    /// rates and delays restart there.
    pub fn run_starts(&self) -> Vec<usize> {
        self.spans().iter().map(|r| r.start).collect()
    }

    /// Whether sample `i` is in a training part.
    pub fn is_train(&self, i: usize) -> bool {
        if self.runs.is_empty() {
            return i < self.train_end;
        }
        self.runs.iter().any(|r| (r.start..r.train_end).contains(&i))
    }

    /// Training samples that enter the fit.
    pub fn train_rows(&self) -> Vec<usize> {
        self.spans().iter().flat_map(|r| r.start..r.train_end).filter(|&i| self.enters_fit(i)).collect()
    }

    /// Whether sample `i` may enter a fit: neither flagged by the quality checks nor a gross
    /// outlier.
    pub fn enters_fit(&self, i: usize) -> bool {
        !self.flagged(i) && self.usable(i)
    }

    /// Whether the quality checks flagged sample `i`.
    pub fn flagged(&self, i: usize) -> bool {
        self.excluded.get(i).copied().unwrap_or(false)
    }

    /// Every held-out sample that may be scored (the `validate` runs of a dataset, or the
    /// end of each run).
    pub fn heldout_rows(&self) -> Vec<usize> {
        self.spans().iter().flat_map(|r| r.train_end..r.end).filter(|&i| self.usable(i)).collect()
    }

    /// Whether sample `i` may be scored at all (not a gross outlier).
    pub fn usable(&self, i: usize) -> bool {
        self.unusable.binary_search(&i).is_err()
    }

    /// Held-out samples the quality checks did not flag.
    pub fn heldout_unflagged(&self) -> Vec<usize> {
        self.spans().iter().flat_map(|r| r.train_end..r.end).filter(|&i| !self.flagged(i)).collect()
    }

    /// `rows` without the samples a delay of `ds` samples leaves uncovered at either end of
    /// their run ([`crate::models::alignment::covered`], per run).
    pub fn covered(&self, rows: &[usize], ds: &[f64]) -> Vec<usize> {
        let spans = self.spans();
        rows.iter()
            .copied()
            .filter(|&i| {
                spans.iter().find(|r| (r.start..r.end).contains(&i)).is_some_and(|r| {
                    let (lo, hi) = crate::models::alignment::covered(r.end - r.start, ds);
                    (r.start + lo..r.start + hi).contains(&i)
                })
            })
            .collect()
    }

    /// `f` applied to each run's part of `v`, joined: a computation that must not cross a join.
    pub fn per_run(&self, v: &[f64], f: impl Fn(&[f64]) -> Vec<f64>) -> Vec<f64> {
        self.spans().iter().flat_map(|r| f(v.get(r.start..r.end).unwrap_or(&[]))).collect()
    }

    /// Spreads of the training part (see [`Scales`]).
    pub fn scales(&self) -> Scales {
        let rows = self.train_rows();
        let dx = self.per_run(&self.input, |v| gradient(v, self.dt));
        let ddx = self.per_run(&dx, |v| gradient(v, self.dt));
        let (x_mean, xs) = mean_std_at(&rows, &self.input);
        let (y_mean, ys) = mean_std_at(&rows, &self.output);
        let u =
            self.command.as_ref().map(|u| rows.iter().filter_map(|&i| u.get(i)).fold(0.0f64, |a, b| a.max(b.abs())));
        Scales {
            x_mean,
            x: xs,
            dx: mean_std_at(&rows, &dx).1,
            ddx: mean_std_at(&rows, &ddx).1,
            y_mean,
            y: ys,
            u: u.filter(|u| *u > 0.0),
            fs: 1.0 / self.dt,
        }
    }
}

/// A recording with gaps in its time column as runs: one per stretch between gaps, each
/// split at `train` as a dataset's runs are, so that the model, its rate estimate and the
/// delays restart after a gap as they do at the start of a recording (a fixed-step model
/// cannot step across missing time). No gap: no runs (one recording, split at `train`).
fn gap_runs(path: &Path, time: &[f64], dt: f64, train: f64) -> Vec<RunSpan> {
    let gaps = crate::io::recording::gaps(time, dt);
    if gaps.is_empty() {
        return Vec::new();
    }
    let ends = gaps.iter().map(|i| i + 1).chain(std::iter::once(time.len()));
    let mut start = 0;
    let mut runs = Vec::with_capacity(gaps.len() + 1);
    for end in ends {
        let train_end = start + ((end - start) as f64 * train).round() as usize;
        runs.push(RunSpan {
            file: path.to_path_buf(),
            role: crate::io::manifest::Role::Train,
            start,
            train_end: train_end.clamp(start, end),
            end,
        });
        start = end;
    }
    runs
}

impl DatasetError {
    /// The training fraction refused, if that is the reason.
    pub fn train_fraction(&self) -> Option<f64> {
        match self {
            Self::TrainFraction(v) => Some(*v),
            Self::In { inner, .. } => inner.train_fraction(),
            _ => None,
        }
    }
}

/// A recording read, checked and split.
#[derive(Clone, Debug)]
pub struct Prepared {
    pub recording: Recording,
    /// What the data-quality checks found (every warning, flagged samples).
    pub quality: Quality,
    pub data: Dataset,
}

/// What a preparation keeps of the recording besides the dataset.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Keeping {
    /// Every channel (a diagnosis looks at the auxiliary ones as possible causes).
    Everything,
    /// The dataset only: the channels no role names are not kept when the file is read, and
    /// those the dataset copied are released from the recording, which keeps its path, line
    /// map, constants and notes (a fit reads nothing else, and a long recording is held once).
    DatasetOnly,
}

/// Read `path`, run the data-quality checks on the channels `ch` and split at `train`;
/// flagged samples are left out of fitting unless `keep_flagged`.
pub fn prepare(
    path: &Path,
    ch: &Channels,
    train: f64,
    keep_flagged: bool,
    keeping: Keeping,
) -> Result<Prepared, DatasetError> {
    let keep = match keeping {
        Keeping::Everything => Keep::All,
        Keeping::DatasetOnly => Keep::roles(ch),
    };
    let mut prepared = prepare_recording(Recording::read_keeping(path, &keep)?, ch, train, keep_flagged)?;
    if keeping == Keeping::DatasetOnly {
        prepared.recording.release(&ch.roles());
    }
    Ok(prepared)
}

/// [`prepare`] for a recording already in memory (a generated one, or a file read before).
pub fn prepare_recording(
    mut recording: Recording,
    ch: &Channels,
    train: f64,
    keep_flagged: bool,
) -> Result<Prepared, DatasetError> {
    recording.apply_constants(ch)?;
    let quality = quality::check(&recording, ch)?;
    let excluded = (!keep_flagged).then(|| quality.excluded());
    let mut data = Dataset::new(&recording, ch, train, excluded)
        .map_err(|e| DatasetError::In { path: recording.path.clone(), inner: Box::new(e) })?;
    data.unusable.clone_from(&quality.unusable);
    Ok(Prepared { recording, quality, data })
}
