//! Where the bundled laboratory data lives.
//!
//! The project's `shared/` folder sits beside the repository (`../shared`). It is found
//! from `$MRC_SHARED_DIR` if set, else by walking up from the current directory and from
//! this crate's source folder.

use std::path::{Path, PathBuf};

/// The `shared/` folder, if it can be found.
pub fn shared_dir() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("MRC_SHARED_DIR") {
        return Some(PathBuf::from(p));
    }
    let starts = [std::env::current_dir().ok(), Some(PathBuf::from(env!("CARGO_MANIFEST_DIR")))];
    for start in starts.into_iter().flatten() {
        for dir in start.ancestors() {
            let cand = dir.join("shared");
            if cand.join("data").is_dir() {
                return Some(cand);
            }
        }
    }
    None
}

/// A file under `shared/data/`, e.g. `dyke/ranran_50.csv`.
pub fn data_file(rel: &str) -> Result<PathBuf, String> {
    let dir = shared_dir().ok_or_else(|| {
        "cannot find the project's shared/ folder (expected beside the repository; set MRC_SHARED_DIR)".to_owned()
    })?;
    let p = dir.join("data").join(rel);
    if p.is_file() {
        Ok(p)
    } else {
        Err(format!("{}: no such data file", p.display()))
    }
}

/// Display helper: the path relative to the current directory when shorter.
pub fn pretty(p: &Path) -> String {
    std::env::current_dir()
        .ok()
        .and_then(|c| p.strip_prefix(&c).ok().map(|r| r.display().to_string()))
        .unwrap_or_else(|| p.display().to_string())
}
