//! Datasets of many recordings identified as one (shared/spec/cli-contract.md "Datasets"):
//! each run is read, checked and split on its own, then the runs are joined end to end with
//! their boundaries kept ([`crate::ident::dataset::RunSpan`]) so that the model's state, the
//! rate estimate and the channel delays restart at every run and no finding spans a join.
//!
//! Held-out data are the `validate` runs when there are any (then every `train` run is
//! fitted whole), otherwise the last `1 − train` of each run.

use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::ident::dataset::{prepare, Dataset, DatasetError, Keeping, Prepared, RunSpan};
use crate::io::manifest::{Manifest, ManifestError, Role, RunPaths};
use crate::io::recording::Channels;
use crate::quality::Quality;

/// One recording of a dataset and the channels to read it with.
#[derive(Clone, Debug)]
pub struct RunSpec {
    pub path: PathBuf,
    pub channels: Channels,
    pub role: Role,
}

#[derive(Debug, Error)]
pub enum RunsError {
    #[error(transparent)]
    Dataset(#[from] DatasetError),
    #[error(transparent)]
    Manifest(#[from] ManifestError),
    #[error("{}: sampled every {dt} s but {} every {first} s; the runs of a dataset share one step", path.display(), first_path.display())]
    Step { path: PathBuf, dt: f64, first_path: PathBuf, first: f64 },
    #[error("{}: has a command channel but {} has none; the runs of a dataset share their channels", with.display(), without.display())]
    Command { with: PathBuf, without: PathBuf },
    #[error(
        "{}: a validate run that {how} the train run {}: its score would not be a held-out one \
         (validate on a recording the fit never saw)", validate.display(), train.display()
    )]
    NotHeldOut { validate: PathBuf, train: PathBuf, how: String },
}

/// The runs of a manifest, with `ch` (the command line's channels) under its `[channels]`;
/// `paths` says whether its files may lie outside its folder.
pub fn from_manifest(path: &Path, ch: &Channels, paths: RunPaths) -> Result<Vec<RunSpec>, RunsError> {
    let m = Manifest::read(path, paths)?;
    let d = &m.channels;
    let base = Channels {
        time: d.time.clone().unwrap_or_else(|| ch.time.clone()),
        input: d.input.clone().unwrap_or_else(|| ch.input.clone()),
        output: d.output.clone().unwrap_or_else(|| ch.output.clone()),
        command: d.command.clone().or_else(|| ch.command.clone()),
        set: merged(&ch.set, &d.set),
    };
    Ok(m.runs
        .into_iter()
        .map(|r| RunSpec {
            path: r.file,
            channels: Channels { set: merged(&base.set, &r.set), ..base.clone() },
            role: r.role,
        })
        .collect())
}

/// `base` with `over`'s entries replacing or adding.
fn merged(base: &[(String, f64)], over: &std::collections::BTreeMap<String, f64>) -> Vec<(String, f64)> {
    let mut out: Vec<(String, f64)> = base.iter().filter(|(n, _)| !over.contains_key(n)).cloned().collect();
    out.extend(over.iter().map(|(n, v)| (n.clone(), *v)));
    out
}

/// A dataset read, checked and split: the joined data and each run's own preparation.
#[derive(Clone, Debug)]
pub struct PreparedRuns {
    /// The joined dataset ([`Dataset::runs`] holds the boundaries); its quality is every run's,
    /// with sample indices into the joined data; its recording is the first run's.
    pub joined: Prepared,
    /// Each run's own preparation; empty for a single recording, which is `joined` itself
    /// (held once: a long recording is not kept twice). [`PreparedRuns::each`] gives both cases.
    pub runs: Vec<Prepared>,
}

impl PreparedRuns {
    /// Each run's preparation (the one recording's for a single run).
    pub fn each(&self) -> &[Prepared] {
        match self.runs.as_slice() {
            [] => std::slice::from_ref(&self.joined),
            runs => runs,
        }
    }
}

/// Read, check and split every run, and join them. A single run is prepared exactly as
/// [`prepare`] does (no run table).
pub fn prepare_runs(
    specs: &[RunSpec],
    train: f64,
    keep_flagged: bool,
    keeping: Keeping,
) -> Result<PreparedRuns, RunsError> {
    let mut runs = Vec::with_capacity(specs.len());
    for s in specs {
        runs.push((prepare(&s.path, &s.channels, train, keep_flagged, keeping)?, s.role));
    }
    join_prepared(runs)
}

/// Join runs already prepared (e.g. from [`crate::ident::dataset::prepare_recording`]), each
/// with its role.
pub fn join_prepared(runs: Vec<(Prepared, Role)>) -> Result<PreparedRuns, RunsError> {
    let (mut runs, roles): (Vec<Prepared>, Vec<Role>) = runs.into_iter().unzip();
    if runs.len() == 1 {
        if let Some(joined) = runs.pop() {
            return Ok(PreparedRuns { joined, runs });
        }
    }
    let first = runs.first().ok_or(DatasetError::NoHeldOut)?;
    let path = |r: &Prepared| r.recording.path.clone();
    for r in runs.iter().skip(1) {
        let (dt, first_dt) = (r.data.dt, first.data.dt);
        if (dt - first_dt).abs() > 0.01 * first_dt {
            return Err(RunsError::Step { path: path(r), dt, first_path: path(first), first: first_dt });
        }
        if r.data.command.is_some() != first.data.command.is_some() {
            let (with, without) = if first.data.command.is_some() { (first, r) } else { (r, first) };
            return Err(RunsError::Command { with: path(with), without: path(without) });
        }
    }
    let any_validate = roles.contains(&Role::Validate);
    if any_validate {
        held_out(&runs, &roles)?;
    }
    let joined = join(&runs, &roles, any_validate);
    let mut quality =
        Quality { warnings: Vec::new(), samples: 0, excluded_samples: 0, notes: Vec::new(), unusable: Vec::new() };
    for (r, span) in runs.iter().zip(&joined.runs) {
        let q = &r.quality;
        quality.warnings.extend(q.warnings.iter().cloned().map(|mut w| {
            w.first_index += span.start;
            w.last_index += span.start;
            w
        }));
        quality.notes.extend(q.notes.iter().cloned());
        quality.unusable.extend(q.unusable.iter().map(|i| i + span.start));
        quality.samples += q.samples;
        quality.excluded_samples += q.excluded_samples;
    }
    let joined = Prepared { recording: first.recording.clone(), quality, data: joined };
    Ok(PreparedRuns { joined, runs })
}

/// Consecutive samples two runs must share, identical in input and output, to overlap: far
/// more than chance makes equal in measured (noisy, many-valued) signals.
const OVERLAP: usize = 64;

/// Refuse a `validate` run that is not held out from the `train` runs: the same file (also
/// under another name or through a link), the same samples (a copy), or a stretch of
/// [`OVERLAP`] samples or more in common with one (a cut of the same recording).
fn held_out(runs: &[Prepared], roles: &[Role]) -> Result<(), RunsError> {
    let train: Vec<&Prepared> = runs.iter().zip(roles).filter(|(_, r)| **r == Role::Train).map(|(p, _)| p).collect();
    // Every aligned window of OVERLAP/2 samples of every train run: a stretch of OVERLAP
    // shared samples holds at least one of them whole.
    let w = OVERLAP / 2;
    let mut windows: std::collections::HashMap<u64, Vec<(usize, usize)>> = std::collections::HashMap::new();
    for (k, t) in train.iter().enumerate() {
        let h = sample_hashes(&t.data);
        for start in (0..h.len().saturating_sub(w - 1)).step_by(w) {
            windows.entry(window_hash(&h[start..start + w])).or_default().push((k, start));
        }
    }
    for v in runs.iter().zip(roles).filter(|(_, r)| **r == Role::Validate).map(|(p, _)| p) {
        let refuse = |t: &Prepared, how: String| RunsError::NotHeldOut {
            validate: v.recording.path.clone(),
            train: t.recording.path.clone(),
            how,
        };
        for t in &train {
            if crate::io::output::same_file(&v.recording.path, &t.recording.path) {
                return Err(refuse(t, "is the same file as".into()));
            }
            let (a, b) = (&v.data, &t.data);
            if a.input == b.input && a.output == b.output && a.command == b.command {
                return Err(refuse(t, "holds the same samples as".into()));
            }
        }
        let h = sample_hashes(&v.data);
        for start in 0..h.len().saturating_sub(w - 1) {
            let Some(hits) = windows.get(&window_hash(&h[start..start + w])) else { continue };
            for &(k, at) in hits {
                let t = train[k];
                let same = |i: usize, j: usize| {
                    v.data.input.get(i) == t.data.input.get(j) && v.data.output.get(i) == t.data.output.get(j)
                };
                if (0..w).all(|i| same(start + i, at + i)) && informative(&v.data, start, w) {
                    let time = v.data.time.get(start).copied().unwrap_or(0.0);
                    return Err(refuse(t, format!("shares samples from {time:.4} s on with")));
                }
            }
        }
    }
    Ok(())
}

/// One hash per sample of the input and output values (their bits).
fn sample_hashes(d: &Dataset) -> Vec<u64> {
    d.input.iter().zip(&d.output).map(|(x, y)| mix(x.to_bits() ^ mix(y.to_bits()))).collect()
}

fn window_hash(h: &[u64]) -> u64 {
    h.iter().fold(0x9E37_79B9_7F4A_7C15, |a, &x| mix(a ^ x))
}

/// SplitMix64's finaliser: a cheap, well-spread 64-bit mix.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Whether samples `start..start + w` vary enough (in input and output) that two recordings
/// share them only by being one: a stretch at rest (the same few levels in every run) is not.
fn informative(d: &Dataset, start: usize, w: usize) -> bool {
    let distinct = |v: &[f64]| {
        let mut bits: Vec<u64> = v.get(start..start + w).unwrap_or(&[]).iter().map(|x| x.to_bits()).collect();
        bits.sort_unstable();
        bits.dedup();
        bits.len()
    };
    distinct(&d.input) >= w / 4 && distinct(&d.output) >= w / 4
}

/// The runs' data end to end (time made to continue, one step after the previous run).
fn join(runs: &[Prepared], roles: &[Role], any_validate: bool) -> Dataset {
    let first = &runs[0].data;
    let mut d = Dataset {
        dt: first.dt,
        time: Vec::new(),
        input: Vec::new(),
        output: Vec::new(),
        command: first.command.as_ref().map(|_| Vec::new()),
        train_end: 0,
        excluded: Vec::new(),
        unusable: Vec::new(),
        rates: None,
        runs: Vec::new(),
    };
    let mut offset_t = 0.0;
    for (r, role) in runs.iter().zip(roles) {
        let (data, start) = (&r.data, d.len());
        let t0 = data.time.first().copied().unwrap_or(0.0);
        d.time.extend(data.time.iter().map(|t| t - t0 + offset_t));
        offset_t = d.time.last().copied().unwrap_or(0.0) + d.dt;
        d.input.extend_from_slice(&data.input);
        d.output.extend_from_slice(&data.output);
        if let (Some(c), Some(u)) = (d.command.as_mut(), data.command.as_ref()) {
            c.extend_from_slice(u);
        }
        d.excluded.extend_from_slice(&data.excluded);
        d.unusable.extend(data.unusable.iter().map(|i| i + start));
        // A recording split at gaps in its time (`Dataset::runs`) stays split.
        for span in data.spans() {
            let (s, end) = (start + span.start, start + span.end);
            let train_end = match (any_validate, role) {
                (false, _) => start + span.train_end,
                (true, Role::Train) => end,
                (true, Role::Validate) => s,
            };
            d.runs.push(RunSpan { file: r.recording.path.clone(), role: *role, start: s, train_end, end });
        }
    }
    // The one split a plot can mark: where the held-out runs begin, or the last run's split.
    d.train_end = d
        .runs
        .iter()
        .rev()
        .take_while(|r| r.role == Role::Validate)
        .last()
        .map_or_else(|| d.runs.last().map_or(0, |r| r.train_end), |r| r.start);
    d
}
