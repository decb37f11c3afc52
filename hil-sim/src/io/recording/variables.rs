//! From a MAT-file's variables to a recording's channels, as labs save them: only the
//! channels a command uses must be valid, so a variable that cannot be a channel is
//! skipped (kept in [`Recording::skipped`] with the reason) rather than refusing the file.
//!
//! - a vector is a channel; a scalar is a constant (a constant channel when a role names it);
//! - a 2-D matrix gives one channel per column, `NAME:K` (K from 1); a matrix wider than it is
//!   tall is taken row by row;
//! - a dSPACE ControlDesk struct gives one channel per signal ([`super::dspace`]);
//! - the recording's length is the one most vectors share (the longer on a tie); vectors of
//!   another length, vectors holding NaN/Inf, text, other structs, complex and sparse arrays
//!   are skipped.

use std::collections::HashMap;
use std::path::Path;

use super::mat::{shape, Kind, Variable};
use super::{Column, Format, Recording, RecordingError, Skipped};

/// Build the recording from the variables `vars` of the MAT-file `path`.
pub(super) fn recording(path: &Path, vars: Vec<Variable>) -> Result<Recording, RecordingError> {
    let p = || path.to_path_buf();
    let mut vectors: Vec<Column> = Vec::new();
    let mut constants: Vec<(String, f64)> = Vec::new();
    let mut skipped: Vec<Skipped> = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for v in vars {
        if !seen.insert(v.name.clone()) {
            return Err(RecordingError::MatVariable { path: p(), variable: v.name, reason: "appears twice".into() });
        }
        match v.kind {
            Kind::Numeric(values) => numeric(v.name, &v.dims, values, &mut vectors, &mut constants, &mut skipped),
            Kind::Struct { fields, elements } => match super::dspace::signals(&fields, &elements) {
                Some(signals) => {
                    for s in signals {
                        if let Kind::Numeric(values) = s.kind {
                            if seen.insert(s.name.clone()) {
                                numeric(s.name, &s.dims, values, &mut vectors, &mut constants, &mut skipped);
                            }
                        }
                    }
                }
                None => skip(&mut skipped, &v.name, "is a struct; only numeric vectors and scalars are read".into()),
            },
            Kind::Text(_) => {
                skip(&mut skipped, &v.name, "is a char array; only numeric vectors and scalars are read".into())
            }
            Kind::Complex => skip(&mut skipped, &v.name, "is complex; channels must be real".into()),
            Kind::Other(what) => {
                skip(&mut skipped, &v.name, format!("is {what}; only numeric vectors and scalars are read"));
            }
        }
    }
    // Vectors holding NaN/Inf cannot be channels.
    vectors.retain(|c| match c.values.iter().position(|x| !x.is_finite()) {
        None => true,
        Some(i) => {
            let e = RecordingError::MatNonFinite {
                path: p(),
                variable: c.name.clone(),
                sample: i as u64 + 1,
                value: c.values[i],
            };
            skipped.push(Skipped { name: c.name.clone(), reason: detail(&e, path) });
            false
        }
    });
    let Some(rows) = common_length(&vectors) else {
        let reason = if skipped.is_empty() {
            "holds no vector variable (no channel)".to_owned()
        } else {
            let names: Vec<String> = skipped.iter().map(|s| format!("`{}`", s.name)).collect();
            format!("holds no usable vector variable (no channel); skipped: {}", names.join(", "))
        };
        return Err(RecordingError::MatFormat { path: p(), reason });
    };
    let first = vectors.iter().find(|c| c.values.len() == rows).map(|c| c.name.clone()).unwrap_or_default();
    vectors.retain(|c| {
        let ok = c.values.len() == rows;
        if !ok {
            let e = RecordingError::MatLength {
                path: p(),
                variable: c.name.clone(),
                len: c.values.len(),
                first: first.clone(),
                first_len: rows,
            };
            skipped.push(Skipped { name: c.name.clone(), reason: detail(&e, path) });
        }
        ok
    });
    if rows < 3 {
        return Err(RecordingError::TooShort { path: p(), rows });
    }
    Ok(Recording {
        path: p(),
        columns: vectors,
        constants,
        lines: super::LineMap::numbered(rows),
        format: Format::Mat,
        skipped,
        unread: Vec::new(),
    })
}

/// An error's text without the leading `path: `.
fn detail(e: &RecordingError, path: &Path) -> String {
    let text = e.to_string();
    let prefix = format!("{}: ", path.display());
    text.strip_prefix(&prefix).map_or(text.clone(), str::to_owned)
}

fn skip(skipped: &mut Vec<Skipped>, name: &str, reason: String) {
    skipped.push(Skipped { name: name.to_owned(), reason: format!("variable `{name}` {reason}") });
}

/// The length most vectors share, the longer on a tie; `None` without vectors.
fn common_length(vectors: &[Column]) -> Option<usize> {
    let mut count: HashMap<usize, usize> = HashMap::new();
    for c in vectors {
        *count.entry(c.values.len()).or_default() += 1;
    }
    count.into_iter().max_by(|a, b| a.1.cmp(&b.1).then(a.0.cmp(&b.0))).map(|(len, _)| len)
}

/// A numeric variable: a vector, a constant, the columns of a matrix, or skipped.
fn numeric(
    name: String,
    dims: &[u64],
    values: Vec<f64>,
    vectors: &mut Vec<Column>,
    constants: &mut Vec<(String, f64)>,
    skipped: &mut Vec<Skipped>,
) {
    let count = dims.iter().try_fold(1u64, |a, &d| a.checked_mul(d));
    if count != Some(values.len() as u64) {
        return skip(skipped, &name, format!("is {} but holds {} values", shape(dims), values.len()));
    }
    if values.is_empty() {
        return skip(skipped, &name, format!("is empty ({})", shape(dims)));
    }
    let long = dims.iter().filter(|&&d| d != 1).count();
    match (values.len(), long, dims) {
        (1, _, _) if values[0].is_finite() => constants.push((name, values[0])),
        (1, _, _) => skip(skipped, &name, format!("is a constant {} (NaN/Inf are not accepted)", values[0])),
        (_, 1, [_, _]) => vectors.push(Column { name, values }),
        (_, _, &[r, c]) => {
            let (r, c) = (r as usize, c as usize);
            // Tall: one channel per column (column-major storage); wide: one per row.
            let (n, k_max) = if r >= c { (r, c) } else { (c, r) };
            for k in 0..k_max {
                let col: Vec<f64> = if r >= c {
                    values[k * r..(k + 1) * r].to_vec()
                } else {
                    (0..n).map(|j| values[j * r + k]).collect()
                };
                vectors.push(Column { name: format!("{name}:{}", k + 1), values: col });
            }
            let reason = format!(
                "is a {} matrix; channels must be vectors (pick one with `{name}:K`, K = 1…{k_max})",
                shape(dims)
            );
            skip(skipped, &name, reason);
        }
        _ => skip(skipped, &name, format!("is a {} array; channels must be vectors", shape(dims))),
    }
}
