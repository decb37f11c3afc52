//! Recordings: CSV files as the lab writes them (quoted header, trailing comma on every
//! row, a column filled only on its first row, as in `shared/data/dyke/`).
//!
//! Every rejection is a [`RecordingError`] naming the file, the line and the reason;
//! nothing is silently dropped.

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
    /// File line of each data row (1-based, header is line 1), for error messages.
    pub lines: Vec<u64>,
}

fn parse_number(text: &str) -> Result<f64, ()> {
    text.parse::<f64>().map_err(|_| ())
}

impl Recording {
    /// Read a CSV recording.
    pub fn read_csv(path: &Path) -> Result<Self, RecordingError> {
        let bytes = std::fs::read(path).map_err(|source| RecordingError::Io { path: path.to_path_buf(), source })?;
        Self::parse_csv(path, &bytes)
    }

    /// Parse CSV bytes; `path` is used in messages only.
    pub fn parse_csv(path: &Path, bytes: &[u8]) -> Result<Self, RecordingError> {
        let p = || path.to_path_buf();
        if bytes.iter().all(|b| b.is_ascii_whitespace()) {
            return Err(RecordingError::Empty { path: p() });
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
        for (i, n) in names.iter().enumerate() {
            if !n.is_empty() && names[..i].contains(n) {
                return Err(RecordingError::Malformed {
                    path: p(),
                    line: 1,
                    reason: format!("column `{n}` appears twice in the header"),
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
                let name = names.get(i).cloned().unwrap_or_default();
                if text.is_empty() {
                    col.push(None);
                    continue;
                }
                let v = parse_number(text).map_err(|_| RecordingError::NotANumber {
                    path: p(),
                    line,
                    column: name.clone(),
                    text: text.to_owned(),
                })?;
                if !v.is_finite() {
                    return Err(RecordingError::NonFinite { path: p(), line, column: name, text: text.to_owned() });
                }
                col.push(Some(v));
            }
            lines.push(line);
        }
        let rows = lines.len();
        if rows == 0 {
            return Err(RecordingError::Empty { path: p() });
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
                    column: if name.is_empty() { format!("#{}", columns.len() + 1) } else { name },
                });
            }
            columns.push(Column { name, values: col.into_iter().flatten().collect() });
        }
        if rows < 3 {
            return Err(RecordingError::TooShort { path: p(), rows });
        }
        Ok(Self { path: path.to_path_buf(), columns, constants, lines })
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
                available: self.names().join(", "),
            }
        })
    }

    /// The time column `name`, checked to increase strictly.
    pub fn time(&self, name: &str) -> Result<&[f64], RecordingError> {
        let t = self.channel(name)?;
        for (i, w) in t.windows(2).enumerate() {
            if let [a, b] = *w {
                if b <= a {
                    return Err(RecordingError::TimeNotIncreasing {
                        path: self.path.clone(),
                        line: self.lines.get(i + 1).copied().unwrap_or(0),
                        prev: a,
                        t: b,
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
}
