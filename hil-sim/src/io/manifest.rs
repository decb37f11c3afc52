//! Dataset manifests (`--dataset runs.toml`, shared/spec/cli-contract.md "Datasets"): the
//! channel defaults under `[channels]` (the flags' names and syntax), then one `[[run]]` per
//! recording with its `file` (relative to the manifest), the constants it lacks (`set`) and
//! its `role` (`train`, the default, or `validate`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use thiserror::Error;

/// What a run is for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Role {
    /// Fitted (all of it when the dataset has `validate` runs, else its first part).
    #[default]
    Train,
    /// Held out: scored, never fitted.
    Validate,
}

impl Role {
    pub fn label(self) -> &'static str {
        match self {
            Self::Train => "train",
            Self::Validate => "validate",
        }
    }
}

/// The `[channels]` table: each absent entry keeps the command line's value.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ChannelDefaults {
    pub time: Option<String>,
    pub input: Option<String>,
    pub output: Option<String>,
    pub command: Option<String>,
    #[serde(default)]
    pub set: BTreeMap<String, f64>,
}

/// One `[[run]]`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RunEntry {
    /// Resolved against the manifest's folder when read.
    pub file: PathBuf,
    #[serde(default)]
    pub set: BTreeMap<String, f64>,
    #[serde(default)]
    pub role: Role,
}

/// A manifest as read.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    #[serde(default)]
    pub channels: ChannelDefaults,
    #[serde(rename = "run", default)]
    pub runs: Vec<RunEntry>,
}

/// Where a manifest's run files may be.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RunPaths {
    /// Inside the manifest's folder (or below it), also once symbolic links are followed: a
    /// manifest handed over with a data set cannot make the tool read (and quote in its
    /// errors) any other file of the machine.
    #[default]
    InsideFolder,
    /// Anywhere (`--allow-outside`).
    Anywhere,
}

#[derive(Debug, Error)]
pub enum ManifestError {
    #[error("{path}: cannot read: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("{path}: {reason}")]
    Format { path: PathBuf, reason: String },
    #[error(
        "{path}: run {index}: `{file}` is outside the manifest's folder; runs are read from inside it \
         (pass --allow-outside to read them from anywhere)"
    )]
    Outside { path: PathBuf, index: usize, file: String },
}

impl Manifest {
    /// Read `path`; run files are made relative to its folder and, unless `paths` allows
    /// others, must lie inside it (checked on the names and again on the files they reach).
    pub fn read(path: &Path, paths: RunPaths) -> Result<Self, ManifestError> {
        crate::io::output::note_input(path);
        let text =
            std::fs::read_to_string(path).map_err(|source| ManifestError::Io { path: path.to_path_buf(), source })?;
        let m = Self::parse(path, &text, paths)?;
        if paths == RunPaths::InsideFolder {
            let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
            if let Ok(root) = dir.canonicalize() {
                for (i, r) in m.runs.iter().enumerate() {
                    // A file that does not exist is reported by its reader; one that does is
                    // judged where its links lead.
                    if r.file.canonicalize().is_ok_and(|f| !f.starts_with(&root)) {
                        return Err(ManifestError::Outside {
                            path: path.to_path_buf(),
                            index: i + 1,
                            file: r.file.display().to_string(),
                        });
                    }
                }
            }
        }
        Ok(m)
    }

    /// Parse manifest text; `path` names it in messages and anchors the run files, which
    /// unless `paths` allows others are relative and do not climb out of its folder.
    pub fn parse(path: &Path, text: &str, paths: RunPaths) -> Result<Self, ManifestError> {
        let fmt = |reason: String| ManifestError::Format { path: path.to_path_buf(), reason };
        let mut m: Self = toml::from_str(text).map_err(|e| {
            let msg = e.message().to_owned();
            let line = e.span().map(|s| text[..s.start.min(text.len())].lines().count().max(1));
            fmt(line.map_or(msg.clone(), |l| format!("line {l}: {msg}")))
        })?;
        if m.runs.is_empty() {
            return Err(fmt("no [[run]]: a dataset needs at least one recording".into()));
        }
        if m.runs.iter().all(|r| r.role == Role::Validate) {
            return Err(fmt("every run is `validate`: nothing to fit".into()));
        }
        let dir = path.parent().unwrap_or(Path::new(""));
        for (i, r) in m.runs.iter_mut().enumerate() {
            if paths == RunPaths::InsideFolder && !stays_inside(&r.file) {
                return Err(ManifestError::Outside {
                    path: path.to_path_buf(),
                    index: i + 1,
                    file: r.file.display().to_string(),
                });
            }
            r.file = dir.join(&r.file);
        }
        Ok(m)
    }
}

/// Whether a relative path stays below its base: not absolute, and no `..` climbs above
/// where it started.
fn stays_inside(rel: &Path) -> bool {
    use std::path::Component;
    let mut depth = 0usize;
    for c in rel.components() {
        match c {
            Component::Normal(_) => depth += 1,
            Component::CurDir => {}
            Component::ParentDir if depth > 0 => depth -= 1,
            Component::ParentDir | Component::RootDir | Component::Prefix(_) => return false,
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_contract_example() {
        let text = r#"
[channels]
time = "Tout"
input = "x_F:1"
output = "forc"
command = "V"

[[run]]
file = "ensaio.A.1.mat"
set = { V = 3.212 }
role = "train"

[[run]]
file = "ensaio.vali.A.1.mat"
set = { V = 2.178 }
role = "validate"
"#;
        let m = Manifest::parse(Path::new("data/runs.toml"), text, RunPaths::InsideFolder).unwrap();
        assert_eq!(m.channels.input.as_deref(), Some("x_F:1"));
        assert_eq!(m.runs.len(), 2);
        assert_eq!(m.runs[0].file, Path::new("data/ensaio.A.1.mat"));
        assert_eq!(m.runs[1].role, Role::Validate);
        assert_eq!(m.runs[1].set.get("V"), Some(&2.178));
        let e = Manifest::parse(Path::new("r.toml"), "[[run]]\nfile = 3\n", RunPaths::InsideFolder)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("r.toml: line 2"), "{e}");
        let e =
            Manifest::parse(Path::new("r.toml"), "[[run]]\nfile = \"a\"\nrole = \"test\"\n", RunPaths::InsideFolder)
                .unwrap_err();
        assert!(e.to_string().contains("r.toml"), "{e}");
    }

    #[test]
    fn run_files_stay_inside_the_manifests_folder_unless_allowed() {
        let run = |file: &str| format!("[[run]]\nfile = \"{file}\"\n");
        for file in ["/etc/shadow", "../../../../../etc/passwd", "a/../../b.csv"] {
            let e = Manifest::parse(Path::new("d/r.toml"), &run(file), RunPaths::InsideFolder).unwrap_err();
            assert!(matches!(e, ManifestError::Outside { index: 1, .. }), "{file}: {e}");
            assert!(e.to_string().contains("--allow-outside"), "{e}");
            assert!(Manifest::parse(Path::new("d/r.toml"), &run(file), RunPaths::Anywhere).is_ok(), "{file}");
        }
        for file in ["a.csv", "sub/b.mat", "sub/../c.csv", "./d.csv"] {
            assert!(Manifest::parse(Path::new("d/r.toml"), &run(file), RunPaths::InsideFolder).is_ok(), "{file}");
        }
    }
}
