//! Recordings: CSV files as the lab writes them (quoted header, trailing comma on every
//! row, a column filled only on its first row, as in `shared/data/dyke/`), and MATLAB
//! level-5 MAT-files (one variable per channel, `recording/mat.rs`). [`Recording::read`] picks the
//! reader by the file's first bytes and its extension.
//!
//! Every rejection is a [`RecordingError`] naming the file, the line (CSV) or the sample
//! (MAT) and the reason; nothing is silently dropped.

pub mod dialect;
mod dspace;
mod lines;
pub use lines::LineMap;
mod mat;
mod select;
mod text;
pub use select::Channels;
mod variables;

use std::path::{Path, PathBuf};

use thiserror::Error;

/// Why a recording could not be read.
#[derive(Debug, Error)]
pub enum RecordingError {
    #[error("{path}: cannot read: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("{path}: the file is empty")]
    Empty { path: PathBuf },
    #[error("{path}:{line}: {reason}")]
    Malformed { path: PathBuf, line: u64, reason: String },
    #[error("{path}:{line}: column `{column}`: `{text}` is not a number{hint}")]
    NotANumber { path: PathBuf, line: u64, column: String, text: String, hint: String },
    #[error(
        "{path}:{line}: field {field} is not a number and no row before it was: not a recording{hint}, or one \
         with more than one header row (its content is not shown)"
    )]
    NotARecording { path: PathBuf, line: u64, field: usize, hint: String },
    #[error("{path}:{line}: column `{column}`: value is {text} (NaN/Inf are not accepted)")]
    NonFinite { path: PathBuf, line: u64, column: String, text: String },
    #[error("{path}:{line}: column `{column}` has no value")]
    MissingValue { path: PathBuf, line: u64, column: String },
    #[error("{path}: no column `{name}` (columns: {available})")]
    MissingColumn { path: PathBuf, name: String, available: String },
    /// A channel the file holds but that cannot be one (skipped when the file was read).
    #[error("{path}: {detail}")]
    Unusable { path: PathBuf, detail: String },
    #[error("{path}: `{name}` is given as a constant but the recording has a channel `{name}`")]
    SetShadows { path: PathBuf, name: String },
    #[error("{path}:{line}: time {t} s does not increase (previous row {prev} s)")]
    TimeNotIncreasing { path: PathBuf, line: u64, prev: f64, t: f64 },
    #[error("{path}: only {rows} data row(s); at least 3 are needed")]
    TooShort { path: PathBuf, rows: usize },
    #[error("{path}: a header but no data rows (the recording is empty)")]
    HeaderOnly { path: PathBuf },
    #[error("{path}: binary data (a NUL byte at byte {offset}): neither CSV text nor a level-5 MAT-file")]
    Binary { path: PathBuf, offset: usize },
    #[error("{path}: truncated MAT-file: an element at byte {offset} runs past the end of its data ({size} bytes in the file)")]
    MatTruncated { path: PathBuf, offset: usize, size: usize },
    #[error("{path}: not a readable MAT-file: {reason}")]
    MatFormat { path: PathBuf, reason: String },
    #[error("{path}: variable `{variable}` {reason}")]
    MatVariable { path: PathBuf, variable: String, reason: String },
    #[error("{path}: variable `{variable}` has {len} samples but `{first}` has {first_len}")]
    MatLength { path: PathBuf, variable: String, len: usize, first: String, first_len: usize },
    #[error("{path}: variable `{variable}`, sample {sample}: value is {value} (NaN/Inf are not accepted)")]
    MatNonFinite { path: PathBuf, variable: String, sample: u64, value: f64 },
    #[error("{path}: sample {sample}: time {t} s does not increase (previous sample {prev} s)")]
    SampleTimeNotIncreasing { path: PathBuf, sample: u64, prev: f64, t: f64 },
    #[error("{path}: column `{name}` is both the {first} and the {second}; they must be different channels")]
    SameChannel { path: PathBuf, name: String, first: &'static str, second: &'static str },
}

/// What kind of file a recording came from: it decides whether a position is a file
/// line (CSV, header = line 1) or a sample number (MAT, first sample = 1).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Format {
    #[default]
    Csv,
    Mat,
}

/// One numeric channel.
#[derive(Clone, Debug, PartialEq)]
pub struct Column {
    pub name: String,
    pub values: Vec<f64>,
}

/// A recording: equally long numeric columns, plus single values given only on the
/// first row (e.g. the Dyke files' sampling frequency `fs`).
#[derive(Clone, Debug, PartialEq)]
pub struct Recording {
    pub path: PathBuf,
    pub columns: Vec<Column>,
    pub constants: Vec<(String, f64)>,
    /// File line of each data row (1-based, header is line 1), for error messages;
    /// for a MAT-file the sample number (1-based).
    pub lines: LineMap,
    /// CSV or MAT: whether `lines` are file lines or sample numbers.
    pub format: Format,
    /// Variables of the file that are not channels (a matrix, text, another length, NaN),
    /// with the reason; an error only when a command asks for one of them.
    pub skipped: Vec<Skipped>,
    /// Channels of the file that were checked but not kept ([`Keep::Named`]), or released.
    pub unread: Vec<String>,
}

/// Which channels a reader keeps in memory. Every column is read and checked either way
/// (a value that is not a number is refused wherever it is); a constant is always kept.
#[derive(Clone, Debug, PartialEq)]
pub enum Keep {
    All,
    /// Only these channels (a command that uses the roles' channels only: a 30-minute log
    /// at 10 kHz is then held as its three or four channels, not all of them).
    Named(Vec<String>),
}

impl Keep {
    /// The channels `ch` names: its roles and the constants it gives.
    pub fn roles(ch: &Channels) -> Self {
        let mut names: Vec<String> = ch.roles().into_iter().map(str::to_owned).collect();
        names.extend(ch.set.iter().map(|(n, _)| n.clone()));
        Self::Named(names)
    }

    pub fn keeps(&self, name: &str) -> bool {
        match self {
            Self::All => true,
            Self::Named(names) => names.iter().any(|n| n == name),
        }
    }
}

/// A variable of the file that is not a channel, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct Skipped {
    pub name: String,
    /// The whole reason, e.g. ``variable `x_F` is a 1501×3 matrix; …``.
    pub reason: String,
}

/// A field as shown in a message: at most 40 characters, control characters escaped.
fn shown(text: &str) -> String {
    let mut s: String = text.chars().take(40).flat_map(char::escape_debug).collect();
    if text.chars().nth(40).is_some() {
        s.push('…');
    }
    s
}

/// Whether bytes look like a level-5 MAT-file (by their header text).
fn is_mat(bytes: &[u8]) -> bool {
    bytes.starts_with(b"MATLAB ")
}

impl Recording {
    /// Read a recording, CSV or MAT-file: a file starting with a MAT-file header, or
    /// named `*.mat`, is read as a MAT-file; anything else as CSV.
    pub fn read(path: &Path) -> Result<Self, RecordingError> {
        Self::read_keeping(path, &Keep::All)
    }

    /// [`Recording::read`] keeping only the channels `keep` names in memory (a text file is
    /// read as it streams; a MAT-file is read whole, then the others are dropped).
    pub fn read_keeping(path: &Path, keep: &Keep) -> Result<Self, RecordingError> {
        use std::io::Read;
        crate::io::output::note_input(path);
        let io = |source| RecordingError::Io { path: path.to_path_buf(), source };
        let mut file = std::fs::File::open(path).map_err(io)?;
        let mut head = Vec::new();
        file.by_ref().take(8).read_to_end(&mut head).map_err(io)?;
        let mat_ext = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("mat"));
        if !(mat_ext || is_mat(&head)) {
            return text::read(path, std::io::Cursor::new(head).chain(file), keep);
        }
        file.read_to_end(&mut head).map_err(io)?;
        let mut rec = Self::parse_mat(path, &head)?;
        let (kept, unread): (Vec<Column>, Vec<Column>) = rec.columns.into_iter().partition(|c| keep.keeps(&c.name));
        rec.columns = kept;
        rec.unread = unread.into_iter().map(|c| c.name).collect();
        Ok(rec)
    }

    /// Parse CSV or MAT bytes (chosen as in [`Recording::read`]); `path` names the file
    /// in messages and its extension counts.
    pub fn parse(path: &Path, bytes: &[u8]) -> Result<Self, RecordingError> {
        let mat_ext = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("mat"));
        if mat_ext || is_mat(bytes) {
            Self::parse_mat(path, bytes)
        } else {
            Self::parse_csv(path, bytes)
        }
    }

    /// Parse level-5 MAT-file bytes: one numeric vector per channel (all the same
    /// length), a scalar variable becomes a constant; `path` is used in messages only.
    pub fn parse_mat(path: &Path, bytes: &[u8]) -> Result<Self, RecordingError> {
        variables::recording(path, mat::read(path, bytes)?)
    }

    /// A recording made in memory (synthetic signals, tests): `columns` must be equally
    /// long; positions in messages are sample numbers.
    pub fn from_columns(path: &Path, columns: Vec<Column>, constants: Vec<(String, f64)>) -> Self {
        let rows = columns.first().map_or(0, |c| c.values.len());
        Self {
            path: path.to_path_buf(),
            columns,
            constants,
            lines: LineMap::numbered(rows),
            format: Format::Mat,
            skipped: Vec::new(),
            unread: Vec::new(),
        }
    }

    /// Where samples `first..=last` (0-based) are, for messages: `rec.csv:12-40` (file
    /// lines) or `rec.mat: samples 11-39` (1-based sample numbers).
    pub fn place(&self, first: usize, last: usize) -> String {
        let line = |i: usize| self.lines.get(i).unwrap_or(i as u64 + 1);
        let (a, b) = (line(first), line(last));
        let range = if a == b { a.to_string() } else { format!("{a}-{b}") };
        match self.format {
            Format::Csv => format!("{}:{range}", self.path.display()),
            Format::Mat if a == b => format!("{}: sample {range}", self.path.display()),
            Format::Mat => format!("{}: samples {range}", self.path.display()),
        }
    }

    /// Keeping channels: every numeric column other than the time, input and output
    /// (the command channel, if any, is one of them).
    pub fn auxiliary(&self, ch: &Channels) -> Vec<&str> {
        self.columns
            .iter()
            .map(|c| c.name.as_str())
            .filter(|n| *n != ch.time && *n != ch.input && *n != ch.output)
            .collect()
    }

    /// The auxiliary channels (as [`Recording::auxiliary`]) with their values.
    pub fn auxiliary_channels(&self, ch: &Channels) -> Vec<(String, Vec<f64>)> {
        let names = self.auxiliary(ch);
        self.columns
            .iter()
            .filter(|c| names.contains(&c.name.as_str()))
            .map(|c| (c.name.clone(), c.values.clone()))
            .collect()
    }

    /// Write the recording as CSV: a header naming the columns and then the constants,
    /// one row per sample, each constant on the first row only (as [`Recording::parse_csv`]
    /// reads it back). Values are written in full (the shortest text that reads back to the
    /// same number).
    pub fn write_csv(&self, w: impl std::io::Write) -> std::io::Result<()> {
        let mut out = csv::Writer::from_writer(w);
        let names = self.columns.iter().map(|c| c.name.as_str()).chain(self.constants.iter().map(|c| c.0.as_str()));
        out.write_record(names)?;
        let mut row: Vec<String> = Vec::with_capacity(self.columns.len() + self.constants.len());
        for k in 0..self.len() {
            row.clear();
            row.extend(self.columns.iter().map(|c| c.values.get(k).map_or_else(String::new, f64::to_string)));
            row.extend(self.constants.iter().map(|c| if k == 0 { c.1.to_string() } else { String::new() }));
            out.write_record(&row)?;
        }
        out.flush()
    }

    /// Read a CSV recording.
    pub fn read_csv(path: &Path) -> Result<Self, RecordingError> {
        crate::io::output::note_input(path);
        let file =
            std::fs::File::open(path).map_err(|source| RecordingError::Io { path: path.to_path_buf(), source })?;
        text::read(path, file, &Keep::All)
    }

    /// Parse text bytes (CSV, or semicolon-, tab- or space-separated, see [`dialect`]);
    /// `path` is used in messages only.
    pub fn parse_csv(path: &Path, bytes: &[u8]) -> Result<Self, RecordingError> {
        text::parse(path, bytes)
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.lines.len()
    }

    pub fn is_empty(&self) -> bool {
        self.lines.is_empty()
    }

    /// Names of the numeric columns.
    pub fn names(&self) -> Vec<&str> {
        self.columns.iter().map(|c| c.name.as_str()).collect()
    }

    /// A column by name (`NAME:K` for column K of a matrix variable). A variable the file
    /// holds but that is not a channel gives the reason it was skipped.
    pub fn channel(&self, name: &str) -> Result<&[f64], RecordingError> {
        if let Some(c) = self.columns.iter().find(|c| c.name == name) {
            return Ok(c.values.as_slice());
        }
        if let Some(s) = self.skipped.iter().find(|s| s.name == name) {
            return Err(RecordingError::Unusable { path: self.path.clone(), detail: s.reason.clone() });
        }
        if self.unread.iter().any(|n| n == name) {
            let detail = format!("channel `{}` was not kept when the file was read", shown(name));
            return Err(RecordingError::Unusable { path: self.path.clone(), detail });
        }
        let mut available = self.names().iter().map(|n| shown(n)).collect::<Vec<_>>().join(", ");
        if self.format == Format::Csv && self.names().iter().enumerate().all(|(i, n)| *n == (i + 1).to_string()) {
            available += "; the file has no header row, so its columns are numbered from 1";
        }
        Err(RecordingError::MissingColumn { path: self.path.clone(), name: name.to_owned(), available })
    }

    /// Move channel `name` out of the recording (for a consumer that keeps it, so that a long
    /// recording is not held twice); errors as [`Recording::channel`].
    pub fn take_channel(&mut self, name: &str) -> Result<Vec<f64>, RecordingError> {
        match self.columns.iter().position(|c| c.name == name) {
            Some(i) => Ok(self.columns.remove(i).values),
            None => self.channel(name).map(<[f64]>::to_vec),
        }
    }

    /// Release channels `names` (a consumer holds copies): they are then [`Recording::unread`].
    pub fn release(&mut self, names: &[&str]) {
        let (gone, kept): (Vec<Column>, Vec<Column>) =
            std::mem::take(&mut self.columns).into_iter().partition(|c| names.contains(&c.name.as_str()));
        self.columns = kept;
        self.unread.extend(gone.into_iter().map(|c| c.name));
    }

    /// The channels `ch` names, checked to be different columns (an output that is also
    /// the input or the time would be "predicted" perfectly).
    pub fn check_roles(&self, ch: &Channels) -> Result<(), RecordingError> {
        let mut roles = vec![("time", ch.time.as_str()), ("input", ch.input.as_str()), ("output", ch.output.as_str())];
        roles.extend(ch.command.as_deref().map(|c| ("command", c)));
        for (i, (first, a)) in roles.iter().enumerate() {
            if let Some((second, _)) = roles[i + 1..].iter().find(|(_, b)| b == a) {
                return Err(RecordingError::SameChannel { path: self.path.clone(), name: shown(a), first, second });
            }
        }
        Ok(())
    }

    /// The time column `name`, checked to increase strictly.
    pub fn time(&self, name: &str) -> Result<&[f64], RecordingError> {
        let t = self.channel(name)?;
        for (i, w) in t.windows(2).enumerate() {
            if let [a, b] = *w {
                if b <= a {
                    let (path, at) = (self.path.clone(), self.lines.get(i + 1).unwrap_or(i as u64 + 2));
                    return Err(match self.format {
                        Format::Csv => RecordingError::TimeNotIncreasing { path, line: at, prev: a, t: b },
                        Format::Mat => RecordingError::SampleTimeNotIncreasing { path, sample: at, prev: a, t: b },
                    });
                }
            }
        }
        Ok(t)
    }

    /// The sampling interval of the time column, seconds: the mean of the intervals within
    /// 0.5–1.5 times the median one ([`nominal_interval`]), so that a gap (or a doubled
    /// stamp) never enters the rate the models step at.
    pub fn sample_interval(&self, time: &str) -> Result<f64, RecordingError> {
        let t = self.time(time)?;
        if t.len() < 2 {
            return Err(RecordingError::TooShort { path: self.path.clone(), rows: t.len() });
        }
        Ok(nominal_interval(t))
    }
}

/// An interval of this many nominal intervals or more is a gap: samples are missing there.
pub const GAP_INTERVALS: f64 = 1.5;

/// The nominal sampling interval of increasing stamps `t`: the mean of the intervals within
/// 0.5–1.5 times the median interval, i.e. the span less the intervals outside that band,
/// over their number (exactly `(last − first) / (n − 1)` when none is outside). 0 for fewer
/// than two stamps.
pub fn nominal_interval(t: &[f64]) -> f64 {
    let dts: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let med = crate::numerics::stats::median(&dts);
    let (mut out_sum, mut out_n) = (0.0, 0usize);
    for d in dts.iter().filter(|d| !(0.5 * med..=1.5 * med).contains(*d)) {
        out_sum += d;
        out_n += 1;
    }
    match (t.first(), t.last()) {
        (Some(a), Some(b)) if dts.len() > out_n => (b - a - out_sum) / (dts.len() - out_n) as f64,
        _ => med,
    }
}

/// The intervals of `t` that are gaps at nominal interval `dt` ([`GAP_INTERVALS`]): `i` for
/// a gap between samples `i` and `i + 1`.
pub fn gaps(t: &[f64], dt: f64) -> Vec<usize> {
    if dt <= 0.0 {
        return Vec::new();
    }
    t.windows(2).enumerate().filter(|(_, w)| (w[1] - w[0]) / dt >= GAP_INTERVALS).map(|(i, _)| i).collect()
}

#[cfg(test)]
mod tests;
