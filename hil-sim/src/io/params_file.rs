//! Parameter files: a model id and its parameters by name, as JSON.
//!
//! ```json
//! { "model": "spencer", "source": "Spencer et al. 1997",
//!   "params": { "c0a": 21.0, "c0b": 3.5, "k0": 46.9, ... } }
//! ```
//! Values are given by the names of `hil-sim models` (a block `name[len]` takes an array
//! of `len` numbers), or `"params"` may be one flat array in that order.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use thiserror::Error;

#[derive(Debug, Error)]
pub enum ParamsFileError {
    #[error("{path}: cannot read: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("{path}: not a valid parameter file: {source}")]
    Json { path: PathBuf, source: serde_json::Error },
    #[error("{path}: {bytes} bytes, more than the {max} a parameter file can need (the largest model has about 100 parameters)")]
    TooLarge { path: PathBuf, bytes: u64, max: u64 },
    #[error("{path}: unknown model `{model}` (see `hil-sim models`)")]
    UnknownModel { path: PathBuf, model: String },
    #[error("{path}: {model}: {reason}")]
    Params { path: PathBuf, model: String, reason: String },
}

/// Values: one flat array, or by name.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(untagged)]
pub enum Values {
    Flat(Vec<f64>),
    Named(BTreeMap<String, Value>),
}

/// One named value: a number or a block.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(untagged)]
pub enum Value {
    One(f64),
    Block(Vec<f64>),
}

/// The file's content.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
pub struct ParamsFile {
    pub model: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source: Option<String>,
    /// Rate estimator the set was fitted with (`--rate` syntax); replay uses it by default.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate: Option<String>,
    /// Input delay the set was fitted with, seconds: replay feeds the model `x(t + delay_s)`
    /// (see `hil_sim::models::alignment`). Absent means 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub delay_s: Option<f64>,
    /// Command delay, seconds: replay feeds the model `u(t + command_delay_s)`. Absent means 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub command_delay_s: Option<f64>,
    /// The channels the set was fitted on (`fit --save`): replay reads them by default, and a
    /// set fitted with a command channel is not replayed without one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub channels: Option<FittedChannels>,
    pub params: Values,
}

/// The channels a set was fitted on, as the flags name them.
#[derive(Clone, Debug, Default, Deserialize, Serialize, PartialEq)]
pub struct FittedChannels {
    pub time: String,
    pub input: String,
    pub output: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub command: Option<String>,
    /// Constants given for channels the recordings lacked (`--set`), by name; a dataset's
    /// runs may each have had their own value, so these are informative only.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub set: BTreeMap<String, f64>,
}

impl FittedChannels {
    /// From the channels of a fit.
    pub fn of(ch: &crate::io::recording::Channels) -> Self {
        Self {
            time: ch.time.clone(),
            input: ch.input.clone(),
            output: ch.output.clone(),
            command: ch.command.clone(),
            set: ch.set.iter().cloned().collect(),
        }
    }
}

/// Split a registry name `w[56]` into (`w`, 56); a plain name is (`name`, 1).
pub fn block(name: &str) -> (&str, usize) {
    if let Some(open) = name.find('[') {
        let len = name[open + 1..].trim_end_matches(']').parse().unwrap_or(1);
        (&name[..open], len)
    } else {
        (name, 1)
    }
}

/// Largest parameter file read, bytes: far above any model's set (a few kB), far below what
/// parsing a hostile file into memory could cost.
pub const MAX_BYTES: u64 = 1 << 20;

impl ParamsFile {
    /// Read and parse a parameter file; files over [`MAX_BYTES`] are refused unread.
    pub fn read(path: &Path) -> Result<Self, ParamsFileError> {
        crate::io::output::note_input(path);
        let io = |source| ParamsFileError::Io { path: path.to_path_buf(), source };
        let bytes = std::fs::metadata(path).map_err(io)?.len();
        if bytes > MAX_BYTES {
            return Err(ParamsFileError::TooLarge { path: path.to_path_buf(), bytes, max: MAX_BYTES });
        }
        let text = std::fs::read_to_string(path).map_err(io)?;
        Self::parse(path, &text)
    }

    /// Parse a parameter file's text (`path` names it in errors).
    pub fn parse(path: &Path, text: &str) -> Result<Self, ParamsFileError> {
        serde_json::from_str(text).map_err(|source| ParamsFileError::Json { path: path.to_path_buf(), source })
    }

    /// The flat f32 vector in the model's parameter order.
    pub fn flat(&self, path: &Path) -> Result<Vec<f32>, ParamsFileError> {
        let info = model_core::registry::find(&self.model)
            .ok_or_else(|| ParamsFileError::UnknownModel { path: path.to_path_buf(), model: self.model.clone() })?;
        let err =
            |reason: String| ParamsFileError::Params { path: path.to_path_buf(), model: self.model.clone(), reason };
        let flat: Vec<f64> = match &self.params {
            Values::Flat(v) => v.clone(),
            Values::Named(map) => {
                let mut out = Vec::with_capacity(info.n_params);
                for name in info.params {
                    let (key, len) = block(name);
                    match (map.get(key), len) {
                        (Some(Value::One(v)), 1) => out.push(*v),
                        (Some(Value::Block(v)), n) if v.len() == n => out.extend(v),
                        (Some(Value::Block(v)), n) => {
                            return Err(err(format!("`{key}` needs {n} values, got {}", v.len())))
                        }
                        (Some(Value::One(_)), n) => return Err(err(format!("`{key}` needs an array of {n} values"))),
                        (None, _) => return Err(err(format!("missing parameter `{key}`"))),
                    }
                }
                let known: Vec<&str> = info.params.iter().map(|n| block(n).0).collect();
                if let Some(extra) = map.keys().find(|k| !known.contains(&k.as_str())) {
                    return Err(err(format!("unknown parameter `{extra}` (expected: {})", known.join(", "))));
                }
                out
            }
        };
        if flat.len() != info.n_params {
            return Err(err(format!("expected {} values, got {}", info.n_params, flat.len())));
        }
        if let Some(i) = flat.iter().position(|v| !v.is_finite()) {
            return Err(err(format!("value #{i} is not finite")));
        }
        // The core runs in f32: a value beyond its range would become infinite there.
        if let Some((i, v)) = flat.iter().enumerate().find(|(_, v)| !(**v as f32).is_finite()) {
            return Err(err(format!("value #{i} = {v:e} is beyond the f32 range of the core (±3.4e38)")));
        }
        Ok(flat.iter().map(|v| *v as f32).collect())
    }

    /// A file for `model` with flat values, written by name.
    pub fn from_flat(model: &str, source: Option<String>, values: &[f32]) -> Option<Self> {
        let info = model_core::registry::find(model)?;
        let mut map = BTreeMap::new();
        let mut it = values.iter().map(|v| f64::from(*v));
        for name in info.params {
            let (key, len) = block(name);
            let v: Vec<f64> = it.by_ref().take(len).collect();
            map.insert(key.to_owned(), if len == 1 { Value::One(*v.first()?) } else { Value::Block(v) });
        }
        Some(Self {
            model: model.to_owned(),
            source,
            rate: None,
            delay_s: None,
            command_delay_s: None,
            channels: None,
            params: Values::Named(map),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn named_and_flat_and_errors() {
        let p = Path::new("p.json");
        let f: ParamsFile =
            serde_json::from_str(r#"{"model":"algebraic","params":{"k":1,"c":2,"alpha":3,"t0":4}}"#).unwrap();
        assert_eq!(f.flat(p).unwrap(), vec![1.0, 2.0, 3.0, 4.0]);
        let back = ParamsFile::from_flat("algebraic", None, &[1.0, 2.0, 3.0, 4.0]).unwrap();
        assert_eq!(back.flat(p).unwrap(), vec![1.0, 2.0, 3.0, 4.0]);
        let f: ParamsFile = serde_json::from_str(r#"{"model":"algebraic","params":[1,2,3,4]}"#).unwrap();
        assert_eq!(f.flat(p).unwrap().len(), 4);
        let f: ParamsFile = serde_json::from_str(r#"{"model":"algebraic","params":{"k":1,"c":2,"alpha":3}}"#).unwrap();
        assert!(f.flat(p).unwrap_err().to_string().contains("missing parameter `t0`"));
        let f: ParamsFile =
            serde_json::from_str(r#"{"model":"algebraic","params":{"k":1,"c":2,"alpha":3,"t0":4,"zz":1}}"#).unwrap();
        assert!(f.flat(p).unwrap_err().to_string().contains("unknown parameter `zz`"));
        let f: ParamsFile = serde_json::from_str(r#"{"model":"nope","params":[]}"#).unwrap();
        assert!(f.flat(p).unwrap_err().to_string().contains("unknown model"));
        assert_eq!(block("w[56]"), ("w", 56));
        assert_eq!(block("k"), ("k", 1));
    }
}
