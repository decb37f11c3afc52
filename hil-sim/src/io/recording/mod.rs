//! Recordings: CSV files as the lab writes them (quoted header, trailing comma on every
//! row, a column filled only on its first row, as in `shared/data/dyke/`), and MATLAB
//! level-5 MAT-files (one variable per channel, `recording/mat.rs`). [`Recording::read`] picks the
//! reader by the file's first bytes and its extension.
//!
//! Every rejection is a [`RecordingError`] naming the file, the line (CSV) or the sample
//! (MAT) and the reason; nothing is silently dropped.

mod mat;

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
    #[error("{path}:{line}: column `{column}`: `{text}` is not a number")]
    NotANumber { path: PathBuf, line: u64, column: String, text: String },
    #[error("{path}:{line}: column `{column}`: value is {text} (NaN/Inf are not accepted)")]
    NonFinite { path: PathBuf, line: u64, column: String, text: String },
    #[error("{path}:{line}: column `{column}` has no value")]
    MissingValue { path: PathBuf, line: u64, column: String },
    #[error("{path}: no column `{name}` (columns: {available})")]
    MissingColumn { path: PathBuf, name: String, available: String },
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

/// Which columns play which role.
#[derive(Clone, Debug, PartialEq)]
pub struct Channels {
    pub time: String,
    pub input: String,
    pub output: String,
    /// Channel driving current/voltage-dependent parameters, if any.
    pub command: Option<String>,
}

impl Default for Channels {
    /// The contract's defaults for an MR clutch: `t`, `b`, `torque`.
    fn default() -> Self {
        Self { time: "t".into(), input: "b".into(), output: "torque".into(), command: None }
    }
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
    pub lines: Vec<u64>,
    /// CSV or MAT: whether `lines` are file lines or sample numbers.
    pub format: Format,
}

fn parse_number(text: &str) -> Result<f64, ()> {
    text.parse::<f64>().map_err(|_| ())
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
        crate::io::output::note_input(path);
        let bytes = std::fs::read(path).map_err(|source| RecordingError::Io { path: path.to_path_buf(), source })?;
        Self::parse(path, &bytes)
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
        mat::parse(path, bytes)
    }

    /// A recording made in memory (synthetic signals, tests): `columns` must be equally
    /// long; positions in messages are sample numbers.
    pub fn from_columns(path: &Path, columns: Vec<Column>, constants: Vec<(String, f64)>) -> Self {
        let rows = columns.first().map_or(0, |c| c.values.len());
        Self { path: path.to_path_buf(), columns, constants, lines: (1..=rows as u64).collect(), format: Format::Mat }
    }

    /// Where samples `first..=last` (0-based) are, for messages: `rec.csv:12-40` (file
    /// lines) or `rec.mat: samples 11-39` (1-based sample numbers).
    pub fn place(&self, first: usize, last: usize) -> String {
        let line = |i: usize| self.lines.get(i).copied().unwrap_or(i as u64 + 1);
        let (a, b) = (line(first), line(last));
        let range = if a == b { a.to_string() } else { format!("{a}-{b}") };
        match self.format {
            Format::Csv => format!("{}:{range}", self.path.display()),
            Format::Mat if a == b => format!("{}: sample {range}", self.path.display()),
            Format::Mat => format!("{}: samples {range}", self.path.display()),
        }
    }

    /// Auxiliary channels: every numeric column other than the time, input and output
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
        let bytes = std::fs::read(path).map_err(|source| RecordingError::Io { path: path.to_path_buf(), source })?;
        Self::parse_csv(path, &bytes)
    }

    /// Parse CSV bytes; `path` is used in messages only.
    pub fn parse_csv(path: &Path, bytes: &[u8]) -> Result<Self, RecordingError> {
        let p = || path.to_path_buf();
        if bytes.iter().all(|b| b.is_ascii_whitespace()) {
            return Err(RecordingError::Empty { path: p() });
        }
        if let Some(offset) = bytes.iter().position(|&b| b == 0) {
            return Err(RecordingError::Binary { path: p(), offset });
        }
        let mut rdr =
            csv::ReaderBuilder::new().has_headers(true).flexible(true).trim(csv::Trim::All).from_reader(bytes);
        let header =
            rdr.headers().map_err(|e| RecordingError::Malformed { path: p(), line: 1, reason: e.to_string() })?.clone();
        // A trailing comma gives a last, unnamed column: ignore unnamed columns that stay empty.
        let names: Vec<String> = header.iter().map(str::to_owned).collect();
        if names.iter().all(String::is_empty) {
            return Err(RecordingError::Malformed {
                path: p(),
                line: 1,
                reason: "the header row has no column names".into(),
            });
        }
        let mut seen = std::collections::HashSet::with_capacity(names.len());
        for n in &names {
            if !n.is_empty() && !seen.insert(n.as_str()) {
                return Err(RecordingError::Malformed {
                    path: p(),
                    line: 1,
                    reason: format!("column `{}` appears twice in the header", shown(n)),
                });
            }
        }
        let width = names.len();
        let mut raw: Vec<Vec<Option<f64>>> = vec![Vec::new(); width];
        let mut lines = Vec::new();
        for rec in rdr.records() {
            let rec = rec.map_err(|e| RecordingError::Malformed {
                path: p(),
                line: e.position().map_or(0, |pos| pos.line()),
                reason: e.to_string(),
            })?;
            let line = rec.position().map_or(0, |pos| pos.line());
            if rec.iter().all(str::is_empty) {
                continue; // blank line
            }
            if rec.len() > width && rec.iter().skip(width).any(|f| !f.is_empty()) {
                return Err(RecordingError::Malformed {
                    path: p(),
                    line,
                    reason: format!("{} fields but the header names {width}", rec.len()),
                });
            }
            for (i, col) in raw.iter_mut().enumerate() {
                let text = rec.get(i).unwrap_or("");
                // The column's name is only looked at (and copied) for an error message.
                let name = || names.get(i).map_or_else(String::new, |n| shown(n));
                if text.is_empty() {
                    col.push(None);
                    continue;
                }
                let v = parse_number(text).map_err(|_| RecordingError::NotANumber {
                    path: p(),
                    line,
                    column: name(),
                    text: shown(text),
                })?;
                if !v.is_finite() {
                    return Err(RecordingError::NonFinite { path: p(), line, column: name(), text: shown(text) });
                }
                col.push(Some(v));
            }
            lines.push(line);
        }
        let rows = lines.len();
        if rows == 0 {
            return Err(RecordingError::HeaderOnly { path: p() });
        }
        let mut columns = Vec::new();
        let mut constants = Vec::new();
        for (name, col) in names.into_iter().zip(raw) {
            let filled = col.iter().filter(|v| v.is_some()).count();
            if filled == 0 && name.is_empty() {
                continue; // trailing comma
            }
            if filled == 1 && rows > 1 && col.first().is_some_and(Option::is_some) {
                constants.push((name, col.first().copied().flatten().unwrap_or(f64::NAN)));
                continue;
            }
            if let Some(missing) = col.iter().position(Option::is_none) {
                return Err(RecordingError::MissingValue {
                    path: p(),
                    line: lines.get(missing).copied().unwrap_or(0),
                    column: if name.is_empty() { format!("#{}", columns.len() + 1) } else { shown(&name) },
                });
            }
            columns.push(Column { name, values: col.into_iter().flatten().collect() });
        }
        if rows < 3 {
            return Err(RecordingError::TooShort { path: p(), rows });
        }
        Ok(Self { path: path.to_path_buf(), columns, constants, lines, format: Format::Csv })
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

    /// A column by name.
    pub fn channel(&self, name: &str) -> Result<&[f64], RecordingError> {
        self.columns.iter().find(|c| c.name == name).map(|c| c.values.as_slice()).ok_or_else(|| {
            RecordingError::MissingColumn {
                path: self.path.clone(),
                name: name.to_owned(),
                available: self.names().iter().map(|n| shown(n)).collect::<Vec<_>>().join(", "),
            }
        })
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
                    let (path, at) = (self.path.clone(), self.lines.get(i + 1).copied().unwrap_or(i as u64 + 2));
                    return Err(match self.format {
                        Format::Csv => RecordingError::TimeNotIncreasing { path, line: at, prev: a, t: b },
                        Format::Mat => RecordingError::SampleTimeNotIncreasing { path, sample: at, prev: a, t: b },
                    });
                }
            }
        }
        Ok(t)
    }

    /// Mean sampling interval of the time column, seconds.
    pub fn mean_dt(&self, time: &str) -> Result<f64, RecordingError> {
        let t = self.time(time)?;
        match (t.first(), t.last()) {
            (Some(a), Some(b)) if t.len() > 1 => Ok((b - a) / (t.len() - 1) as f64),
            _ => Err(RecordingError::TooShort { path: self.path.clone(), rows: t.len() }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(s: &str) -> Result<Recording, RecordingError> {
        Recording::parse_csv(Path::new("rec.csv"), s.as_bytes())
    }

    #[test]
    fn written_csv_reads_back_the_same_values() {
        let col = |name: &str, values: Vec<f64>| Column { name: name.into(), values };
        let columns = vec![col("t", vec![0.0, 0.0005, 0.001]), col("b", vec![0.1 + 0.2, -1e-7, 12345.678901])];
        let rec = Recording::from_columns(Path::new("mem"), columns, vec![("fs".into(), 2000.0)]);
        let mut out = Vec::new();
        rec.write_csv(&mut out).unwrap();
        let text = String::from_utf8(out).unwrap();
        assert!(text.starts_with("t,b,fs\n0,0.30000000000000004,2000\n"), "{text}");
        let back = parse(&text).unwrap();
        assert_eq!(back.columns, rec.columns);
        assert_eq!(back.constants, rec.constants);
    }

    #[test]
    fn reads_dyke_quirks() {
        let r = parse("\"t\",\"D\",\"fs\",\"F\",\n0,1.5,3004.8,10,\n0.1,1.6,,11,\n0.2,1.7,,12,\n").unwrap();
        assert_eq!(r.names(), vec!["t", "D", "F"]);
        assert_eq!(r.constants, vec![("fs".to_owned(), 3004.8)]);
        assert_eq!(r.channel("F").unwrap(), &[10.0, 11.0, 12.0]);
        assert!((r.mean_dt("t").unwrap() - 0.1).abs() < 1e-12);
    }

    #[test]
    fn errors_name_line_and_reason() {
        let msg = |s: &str| parse(s).unwrap_err().to_string();
        assert!(msg("").contains("empty"));
        assert!(msg("t,x\n").contains("empty"));
        let m = msg("t,x\n0,1\n0.1,abc\n0.2,3\n");
        assert!(m.contains("rec.csv:3") && m.contains("`abc` is not a number"), "{m}");
        let m = msg("t,x\n0,1\n0.1,NaN\n0.2,3\n");
        assert!(m.contains("rec.csv:3") && m.contains("NaN"), "{m}");
        let m = msg("t,x\n0,1\n0.1,\n0.2,3\n");
        assert!(m.contains("rec.csv:3") && m.contains("no value"), "{m}");
        let r = parse("t,x\n0,1\n0.1,2\n0.1,3\n").unwrap();
        let m = r.time("t").unwrap_err().to_string();
        assert!(m.contains("rec.csv:4") && m.contains("does not increase"), "{m}");
        let m = r.channel("F").unwrap_err().to_string();
        assert!(m.contains("no column `F`") && m.contains("t, x"), "{m}");
    }

    #[test]
    fn reads_the_real_dyke_file() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/dyke/ranran_50.csv");
        let r = Recording::read_csv(&path).unwrap();
        assert_eq!(r.len(), 74_068);
        assert_eq!(r.names(), vec!["t", "A", "D", "Y", "V", "F"]);
        assert!(r.time("t").is_ok());
        let fs = r.constants.iter().find(|(n, _)| n == "fs").map(|c| c.1).unwrap();
        assert!((1.0 / r.mean_dt("t").unwrap() - fs).abs() < 1.0);
    }

    fn corpus(name: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus").join(name)
    }

    #[test]
    fn reads_mat_files_plain_and_compressed() {
        let a = Recording::read(&corpus("good.mat")).unwrap();
        let b = Recording::read(&corpus("good_compressed.mat")).unwrap();
        assert_eq!(a.format, Format::Mat);
        assert_eq!(a.names(), vec!["t", "b", "torque", "speed", "temperature"]);
        assert_eq!(a.constants, vec![("fs".to_owned(), 1000.0)]);
        assert_eq!(a.len(), 50);
        assert_eq!(a.columns, b.columns);
        assert!((a.mean_dt("t").unwrap() - 0.001).abs() < 1e-12);
        assert_eq!(a.channel("temperature").unwrap()[3], 23.0);
        assert!((a.channel("speed").unwrap()[49] - 10.0).abs() < 1e-6);
        let ch = Channels::default();
        assert_eq!(a.auxiliary(&ch), vec!["speed", "temperature"]);
        assert_eq!(a.place(0, 2), format!("{}: samples 1-3", corpus("good.mat").display()));
    }

    #[test]
    fn mat_errors_name_file_variable_and_sample() {
        let msg = |n: &str| Recording::read(&corpus(n)).unwrap_err().to_string();
        let m = msg("truncated.mat");
        assert!(m.contains("truncated.mat") && m.contains("truncated MAT-file"), "{m}");
        let m = msg("matrix_shape.mat");
        assert!(m.contains("variable `torque` is a 3×4 matrix"), "{m}");
        let m = msg("length_mismatch.mat");
        assert!(m.contains("variable `torque` has 40 samples but `t` has 50"), "{m}");
        let m = msg("nan.mat");
        assert!(m.contains("variable `torque`, sample 17: value is NaN"), "{m}");
        let m = msg("char_variable.mat");
        assert!(m.contains("variable `notes` is a char array"), "{m}");
        let m = msg("garbage.bin");
        assert!(m.contains("garbage.bin") && m.contains("binary data"), "{m}");
        let r = Recording::read(&corpus("time_not_increasing.mat")).unwrap();
        let m = r.time("t").unwrap_err().to_string();
        assert!(m.contains("time_not_increasing.mat: sample 31: time"), "{m}");
        // A `.mat` name with text inside is judged as a MAT-file.
        let m = Recording::parse(Path::new("x.mat"), b"t,b\n0,1\n").unwrap_err().to_string();
        assert!(m.contains("x.mat") && m.contains("shorter than the 128-byte"), "{m}");
        // Big-endian files are read too: the plain file with every field byte-swapped.
        let le = std::fs::read(corpus("good.mat")).unwrap();
        let be = to_big_endian(&le);
        let r = Recording::parse(Path::new("be.mat"), &be).unwrap();
        assert_eq!(r.columns, Recording::parse(Path::new("le.mat"), &le).unwrap().columns);
    }

    /// Byte-swap an uncompressed little-endian level-5 file (tags, flags, dims and data).
    fn to_big_endian(le: &[u8]) -> Vec<u8> {
        fn width(t: u32) -> usize {
            match t {
                3 | 4 => 2,
                5..=7 => 4,
                9 | 12 | 13 => 8,
                _ => 1,
            }
        }
        fn elements(src: &[u8], out: &mut Vec<u8>) {
            let mut pos = 0;
            while pos + 8 <= src.len() {
                let first = u32::from_le_bytes(src[pos..pos + 4].try_into().unwrap());
                let (t, n, head, data_at) = if first >> 16 != 0 {
                    (first & 0xFFFF, (first >> 16) as usize, 4, pos + 4)
                } else {
                    (first, u32::from_le_bytes(src[pos + 4..pos + 8].try_into().unwrap()) as usize, 8, pos + 8)
                };
                if head == 4 {
                    out.extend_from_slice(&((n as u32) << 16 | t).to_be_bytes());
                } else {
                    out.extend_from_slice(&t.to_be_bytes());
                    out.extend_from_slice(&(n as u32).to_be_bytes());
                }
                let data = &src[data_at..data_at + n];
                if t == 14 {
                    elements(data, out);
                } else {
                    let w = width(t);
                    for c in data.chunks(w) {
                        out.extend(c.iter().rev());
                    }
                }
                let padded = if head == 4 { 4 } else { n.div_ceil(8) * 8 };
                out.extend(std::iter::repeat_n(0u8, padded - n));
                pos = data_at + padded;
            }
        }
        let mut out = le[..128].to_vec();
        out[124] = 0x01;
        out[125] = 0x00;
        out[126] = b'M';
        out[127] = b'I';
        elements(&le[128..], &mut out);
        out
    }
}
