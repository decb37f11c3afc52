//! CSV and other text recordings: a header row naming the columns (or none: then the
//! columns are numbered from 1), one numeric column per channel, a column filled only on
//! its first row is a constant, a trailing separator on every row is ignored. The
//! separator and decimal mark are found by [`super::dialect`].

use std::path::Path;

use super::dialect::{self, Dialect};
use super::{shown, Column, Format, Recording, RecordingError};

/// Parse text bytes; `path` is used in messages only.
pub(super) fn parse(path: &Path, bytes: &[u8]) -> Result<Recording, RecordingError> {
    let p = || path.to_path_buf();
    if bytes.iter().all(|b| b.is_ascii_whitespace()) {
        return Err(RecordingError::Empty { path: p() });
    }
    if let Some(offset) = bytes.iter().position(|&b| b == 0) {
        return Err(RecordingError::Binary { path: p(), offset });
    }
    let (dialect, rewritten) = match std::str::from_utf8(bytes) {
        // CRLF text is rewritten too: the csv crate counts its lines one short.
        Ok(text) => match Dialect::sniff(text) {
            Dialect::Comma if !text.contains('\r') => (Dialect::Comma, None),
            d => (d, Some(dialect::to_csv(text, d))),
        },
        Err(_) => (Dialect::Comma, None),
    };
    let bytes = rewritten.as_ref().map_or(bytes, |s| s.as_bytes());
    let hint = match dialect {
        Dialect::Comma => String::new(),
        d => format!(" (read as {}, decimal commas allowed)", d.describe()),
    };
    let mut rdr = csv::ReaderBuilder::new().has_headers(false).flexible(true).trim(csv::Trim::All).from_reader(bytes);
    let mut records = rdr.records();
    let bad_row = |e: csv::Error| RecordingError::Malformed {
        path: p(),
        line: e.position().map_or(0, |pos| pos.line()),
        reason: e.to_string(),
    };
    // The header: the first non-blank row, unless it holds only numbers.
    let mut first = None;
    for rec in records.by_ref() {
        let rec = rec.map_err(bad_row)?;
        if !rec.iter().all(str::is_empty) {
            first = Some(rec);
            break;
        }
    }
    let Some(first) = first else { return Err(RecordingError::Empty { path: p() }) };
    let numeric_row = first.iter().filter(|f| !f.is_empty()).all(|f| f.parse::<f64>().is_ok());
    let (names, headerless): (Vec<String>, bool) = if numeric_row {
        ((1..=first.len()).map(|i| i.to_string()).collect(), true)
    } else {
        (first.iter().map(str::to_owned).collect(), false)
    };
    if names.iter().all(String::is_empty) {
        return Err(RecordingError::Malformed {
            path: p(),
            line: 1,
            reason: "the header row has no column names".into(),
        });
    }
    let header_line = first.position().map_or(1, |pos| pos.line());
    let width = names.len();
    let mut raw: Vec<Vec<Option<f64>>> = vec![Vec::new(); width];
    let mut lines = Vec::new();
    let data = headerless.then_some(Ok(first)).into_iter().chain(records);
    for rec in data {
        let rec = rec.map_err(bad_row)?;
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
        for (i, col) in raw.iter_mut().enumerate() {
            let text = rec.get(i).unwrap_or("");
            // The column's name is only looked at (and copied) for an error message.
            let name = || names.get(i).map_or_else(String::new, |n| shown(n));
            if text.is_empty() {
                col.push(None);
                continue;
            }
            // Until a row has been read as numbers the file is not known to be a recording
            // (a manifest or a flag may name any file): nothing of it is quoted.
            let v = text.parse::<f64>().map_err(|_| match lines.is_empty() {
                // The separator a field seems to hold is said; the field itself is not.
                true => RecordingError::NotARecording {
                    path: p(),
                    line,
                    field: i + 1,
                    hint: not_a_number_hint(text, dialect, &hint),
                },
                false => RecordingError::NotANumber {
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
            col.push(Some(v));
        }
        lines.push(line);
    }
    let rows = lines.len();
    if rows == 0 {
        return Err(RecordingError::HeaderOnly { path: p() });
    }
    // The header is judged once rows of numbers show the file is a recording.
    no_repeated_name(path, &names, header_line)?;
    let (columns, constants) = columns(path, names, raw, &lines)?;
    if rows < 3 {
        return Err(RecordingError::TooShort { path: p(), rows });
    }
    Ok(Recording { path: p(), columns, constants, lines, format: Format::Csv, skipped: Vec::new() })
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

/// The parsed fields as channels and constants (a column filled on its first row only); an
/// unnamed column left empty is a trailing separator.
#[allow(clippy::type_complexity)]
fn columns(
    path: &Path,
    names: Vec<String>,
    raw: Vec<Vec<Option<f64>>>,
    lines: &[u64],
) -> Result<(Vec<Column>, Vec<(String, f64)>), RecordingError> {
    let rows = lines.len();
    let mut columns = Vec::new();
    let mut constants = Vec::new();
    for (name, col) in names.into_iter().zip(raw) {
        let filled = col.iter().filter(|v| v.is_some()).count();
        if filled == 0 && name.is_empty() {
            continue; // trailing separator
        }
        if filled == 1 && rows > 1 && col.first().is_some_and(Option::is_some) {
            constants.push((name, col.first().copied().flatten().unwrap_or(f64::NAN)));
            continue;
        }
        if let Some(missing) = col.iter().position(Option::is_none) {
            return Err(RecordingError::MissingValue {
                path: path.to_path_buf(),
                line: lines.get(missing).copied().unwrap_or(0),
                column: if name.is_empty() { format!("#{}", columns.len() + 1) } else { shown(&name) },
            });
        }
        columns.push(Column { name, values: col.into_iter().flatten().collect() });
    }
    Ok((columns, constants))
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
