//! CSV and other text recordings: a header row naming the columns (or none: then the
//! columns are numbered from 1), one numeric column per channel, a column filled only on
//! its first row is a constant, a trailing separator on every row is ignored. The
//! separator and decimal mark are found by [`super::dialect`].

use std::io::{BufRead, BufReader, Read};
use std::path::Path;

use super::dialect::{self, Dialect};
use super::lines::LineMap;
use super::{shown, Column, Format, Keep, Recording, RecordingError};

/// Bytes read before parsing, to judge the dialect and refuse binary files early.
const HEAD: u64 = 1 << 20;

/// Parse text bytes; `path` is used in messages only.
pub(super) fn parse(path: &Path, bytes: &[u8]) -> Result<Recording, RecordingError> {
    read(path, bytes, &Keep::All)
}

/// Read a text recording from `source` as it streams: memory holds the channels `keep` names
/// (8 bytes a value) and a few words per file, never the text. Every column is still checked,
/// kept or not; `path` is used in messages only.
pub(super) fn read(path: &Path, mut source: impl Read, keep: &Keep) -> Result<Recording, RecordingError> {
    let p = || path.to_path_buf();
    let io = |source| RecordingError::Io { path: p(), source };
    let mut head = Vec::new();
    source.by_ref().take(HEAD).read_to_end(&mut head).map_err(io)?;
    if let Some(offset) = head.iter().position(|&b| b == 0) {
        return Err(RecordingError::Binary { path: p(), offset });
    }
    let text = match std::str::from_utf8(&head) {
        Ok(text) => text,
        // The head may end inside a character; what comes before it is judged.
        Err(e) => std::str::from_utf8(head.get(..e.valid_up_to()).unwrap_or_default()).unwrap_or_default(),
    };
    let dialect = Dialect::sniff(text);
    let hint = match dialect {
        Dialect::Comma => String::new(),
        d => format!(" (read as {}, decimal commas allowed)", d.describe()),
    };
    let lines = CsvLines::new(std::io::Cursor::new(head).chain(source), dialect);
    let mut rdr = csv::ReaderBuilder::new().has_headers(false).flexible(true).trim(csv::Trim::All).from_reader(lines);
    let mut rec = csv::StringRecord::new();
    let next = |rdr: &mut csv::Reader<_>, rec: &mut csv::StringRecord| -> Result<bool, RecordingError> {
        rdr.read_record(rec).map_err(|e| row_error(path, e, rdr.get_ref()))
    };
    // The header: the first non-blank row, unless it holds only numbers.
    let mut found = false;
    while next(&mut rdr, &mut rec)? {
        if !rec.iter().all(str::is_empty) {
            found = true;
            break;
        }
    }
    if !found {
        return Err(RecordingError::Empty { path: p() });
    }
    let numeric_row = rec.iter().filter(|f| !f.is_empty()).all(|f| f.parse::<f64>().is_ok());
    let (names, headerless): (Vec<String>, bool) = if numeric_row {
        ((1..=rec.len()).map(|i| i.to_string()).collect(), true)
    } else {
        (rec.iter().map(str::to_owned).collect(), false)
    };
    if names.iter().all(String::is_empty) {
        return Err(RecordingError::Malformed {
            path: p(),
            line: 1,
            reason: "the header row has no column names".into(),
        });
    }
    let header_line = rec.position().map_or(1, |pos| pos.line());
    let width = names.len();
    let mut fields: Vec<Field> = names.iter().map(|n| Field::new(keep.keeps(n))).collect();
    let mut lines = LineMap::default();
    let mut pending = headerless;
    while pending || next(&mut rdr, &mut rec)? {
        pending = false;
        let line = rec.position().map_or(0, |pos| pos.line());
        if rec.iter().all(str::is_empty) {
            continue; // blank line
        }
        if rec.len() > width && rec.iter().skip(width).any(|f| !f.is_empty()) {
            return Err(RecordingError::Malformed {
                path: p(),
                line,
                reason: format!("{} fields but the header names {width}{hint}", rec.len()),
            });
        }
        let row = lines.len();
        for (i, field) in fields.iter_mut().enumerate() {
            let text = rec.get(i).unwrap_or("");
            if text.is_empty() {
                field.missing(row);
                continue;
            }
            // The column's name is only looked at (and copied) for an error message.
            let name = || names.get(i).map_or_else(String::new, |n| shown(n));
            // Until a row has been read as numbers the file is not known to be a recording
            // (a manifest or a flag may name any file): nothing of it is quoted.
            let v = text.parse::<f64>().map_err(|_| match row {
                // The separator a field seems to hold is said; the field itself is not.
                0 => RecordingError::NotARecording {
                    path: p(),
                    line,
                    field: i + 1,
                    hint: not_a_number_hint(text, dialect, &hint),
                },
                _ => RecordingError::NotANumber {
                    path: p(),
                    line,
                    column: name(),
                    text: shown(text),
                    hint: not_a_number_hint(text, dialect, &hint),
                },
            })?;
            if !v.is_finite() {
                return Err(RecordingError::NonFinite { path: p(), line, column: name(), text: shown(text) });
            }
            field.value(row, v);
        }
        lines.push(line);
    }
    let rows = lines.len();
    if rows == 0 {
        return Err(RecordingError::HeaderOnly { path: p() });
    }
    // The header is judged once rows of numbers show the file is a recording.
    no_repeated_name(path, &names, header_line)?;
    let (columns, constants, unread) = columns(path, names, fields, &lines)?;
    if rows < 3 {
        return Err(RecordingError::TooShort { path: p(), rows });
    }
    Ok(Recording { path: p(), columns, constants, lines, format: Format::Csv, skipped: Vec::new(), unread })
}

/// A CSV reader's error as a recording's: a NUL byte the stream met makes the file binary.
fn row_error<R: BufRead>(path: &Path, e: csv::Error, lines: &CsvLines<R>) -> RecordingError {
    match lines.nul_at {
        Some(offset) => RecordingError::Binary { path: path.to_path_buf(), offset },
        None => RecordingError::Malformed {
            path: path.to_path_buf(),
            line: e.position().map_or(0, |pos| pos.line()),
            reason: e.to_string(),
        },
    }
}

/// The text of a recording as CSV, line by line as it is read ([`dialect::line_to_csv`]); a
/// NUL byte ends it with an error and its offset.
struct CsvLines<R> {
    inner: R,
    dialect: Dialect,
    line: Vec<u8>,
    out: Vec<u8>,
    pos: usize,
    /// Bytes of the source consumed.
    offset: usize,
    nul_at: Option<usize>,
}

impl<R: Read> CsvLines<BufReader<R>> {
    fn new(source: R, dialect: Dialect) -> Self {
        let inner = BufReader::with_capacity(1 << 16, source);
        Self { inner, dialect, line: Vec::new(), out: Vec::new(), pos: 0, offset: 0, nul_at: None }
    }
}

impl<R: BufRead> Read for CsvLines<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        while self.pos >= self.out.len() {
            self.line.clear();
            self.out.clear();
            self.pos = 0;
            if self.inner.read_until(b'\n', &mut self.line)? == 0 {
                return Ok(0);
            }
            if let Some(i) = self.line.iter().position(|&b| b == 0) {
                self.nul_at = Some(self.offset + i);
                return Err(std::io::Error::new(std::io::ErrorKind::InvalidData, "a NUL byte"));
            }
            self.offset += self.line.len();
            dialect::line_to_csv(&self.line, self.dialect, &mut self.out);
        }
        let chunk = self.out.get(self.pos..).unwrap_or_default();
        let n = chunk.len().min(buf.len());
        buf[..n].copy_from_slice(&chunk[..n]);
        self.pos += n;
        Ok(n)
    }
}

/// One column as it is read: its values if it is kept (NaN where a row has none: a value
/// read is always finite), and what decides whether it is a channel or a constant.
struct Field {
    values: Option<Vec<f64>>,
    filled: usize,
    /// The first row's value.
    first: Option<f64>,
    first_missing: Option<usize>,
}

impl Field {
    fn new(kept: bool) -> Self {
        Self { values: kept.then(Vec::new), filled: 0, first: None, first_missing: None }
    }

    fn value(&mut self, row: usize, v: f64) {
        self.filled += 1;
        if row == 0 {
            self.first = Some(v);
        }
        if let Some(values) = &mut self.values {
            values.push(v);
        }
    }

    fn missing(&mut self, row: usize) {
        self.first_missing.get_or_insert(row);
        if let Some(values) = &mut self.values {
            values.push(f64::NAN);
        }
    }
}

/// A header naming no column twice.
fn no_repeated_name(path: &Path, names: &[String], line: u64) -> Result<(), RecordingError> {
    let mut seen = std::collections::HashSet::with_capacity(names.len());
    match names.iter().find(|n| !n.is_empty() && !seen.insert(n.as_str())) {
        Some(n) => Err(RecordingError::Malformed {
            path: path.to_path_buf(),
            line,
            reason: format!("column `{}` appears twice in the header", shown(n)),
        }),
        None => Ok(()),
    }
}

/// The parsed fields as channels, constants (a column filled on its first row only) and the
/// names of the channels not kept; an unnamed column left empty is a trailing separator.
#[allow(clippy::type_complexity)]
fn columns(
    path: &Path,
    names: Vec<String>,
    fields: Vec<Field>,
    lines: &LineMap,
) -> Result<(Vec<Column>, Vec<(String, f64)>, Vec<String>), RecordingError> {
    let rows = lines.len();
    let (mut columns, mut constants, mut unread) = (Vec::new(), Vec::new(), Vec::new());
    for (name, field) in names.into_iter().zip(fields) {
        if field.filled == 0 && name.is_empty() {
            continue; // trailing separator
        }
        if let (true, Some(v)) = (rows > 1 && field.filled == 1, field.first) {
            constants.push((name, v));
            continue;
        }
        if let Some(missing) = field.first_missing {
            return Err(RecordingError::MissingValue {
                path: path.to_path_buf(),
                line: lines.get(missing).unwrap_or(0),
                column: if name.is_empty() { format!("#{}", columns.len() + unread.len() + 1) } else { shown(&name) },
            });
        }
        match field.values {
            Some(values) => columns.push(Column { name, values }),
            None => unread.push(name),
        }
    }
    Ok((columns, constants, unread))
}

/// What to add to a "not a number" message: the dialect the file was read in, or the
/// separator a comma-separated field seems to hold.
fn not_a_number_hint(text: &str, dialect: Dialect, read_as: &str) -> String {
    if dialect != Dialect::Comma {
        return read_as.to_owned();
    }
    let inner = if text.contains(';') {
        Some("semicolons")
    } else if text.contains('\t') {
        Some("tabs")
    } else if text.trim().contains(' ') {
        Some("spaces")
    } else {
        None
    };
    inner.map_or_else(String::new, |s| format!(" (the field holds {s}: is the file separated by {s}, not commas?)"))
}
