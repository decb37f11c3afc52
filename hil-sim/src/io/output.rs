//! Every file the tool writes goes through here: an output that is the same file as an input
//! read in this run (also through a symlink or a hard link) is refused, an existing symlink
//! where the output would go is refused, and the bytes go to a temporary file in the same
//! folder that is then renamed over the output, so a failed write leaves the old file whole.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use thiserror::Error;

/// Why an output was not written.
#[derive(Debug, Error)]
pub enum OutputError {
    #[error("{path}: is the input {input}; refusing to overwrite it (choose another output)")]
    SameAsInput { path: PathBuf, input: PathBuf },
    #[error("{path}: is a symbolic link; refusing to write through it")]
    Symlink { path: PathBuf },
    #[error("{path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
}

/// The files read in this process; outputs may not be any of them.
static INPUTS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Note `path` as an input: later outputs that are the same file are refused. The readers
/// of recordings and parameter files call this.
pub fn note_input(path: &Path) {
    if let Ok(mut v) = INPUTS.lock() {
        if !v.iter().any(|p| p == path) {
            v.push(path.to_path_buf());
        }
    }
}

/// Whether two paths name the same existing file (device and inode where the OS tells,
/// else the canonical paths).
pub fn same_file(a: &Path, b: &Path) -> bool {
    let (Ok(ma), Ok(mb)) = (std::fs::metadata(a), std::fs::metadata(b)) else {
        return false;
    };
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        let _ = (&ma, &mb);
        ma.dev() == mb.dev() && ma.ino() == mb.ino()
    }
    #[cfg(not(unix))]
    {
        let _ = (ma, mb);
        matches!((a.canonicalize(), b.canonicalize()), (Ok(x), Ok(y)) if x == y)
    }
}

/// Refuse `path` if it is a symlink or the same file as an input.
pub fn check(path: &Path) -> Result<(), OutputError> {
    if std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink()) {
        return Err(OutputError::Symlink { path: path.into() });
    }
    let inputs = INPUTS.lock().map(|v| v.clone()).unwrap_or_default();
    match inputs.into_iter().find(|i| same_file(i, path)) {
        Some(input) => Err(OutputError::SameAsInput { path: path.into(), input }),
        None => Ok(()),
    }
}

/// Create the output folder `dir` (and its parents).
pub fn create_dir(dir: &Path) -> Result<(), OutputError> {
    std::fs::create_dir_all(dir).map_err(|source| OutputError::Io { path: dir.into(), source })
}

/// A file written as it goes (a journal, a log), not swapped in whole: refused as
/// [`check`] refuses, its folder made, opened without following a symbolic link put there
/// after the check.
pub fn create_stream(path: &Path) -> Result<std::fs::File, OutputError> {
    check(path)?;
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    create_dir(dir)?;
    let mut o = std::fs::OpenOptions::new();
    o.write(true).create(true).truncate(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        o.custom_flags(libc::O_NOFOLLOW);
    }
    o.open(path).map_err(|source| OutputError::Io { path: path.into(), source })
}

/// Write `bytes` to `path` (its folder created if missing), through a temporary file.
pub fn write(path: &Path, bytes: impl AsRef<[u8]>) -> Result<(), OutputError> {
    write_with(path, |w| w.write_all(bytes.as_ref()))
}

/// Write `path` with `fill` (buffered), through a temporary file renamed at the end.
pub fn write_with(
    path: &Path,
    fill: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> std::io::Result<()>,
) -> Result<(), OutputError> {
    check(path)?;
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    create_dir(dir)?;
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    let io = |source| OutputError::Io { path: path.into(), source };
    let file = std::fs::OpenOptions::new().write(true).create_new(true).open(&tmp).map_err(io)?;
    let mut w = std::io::BufWriter::new(file);
    let done = fill(&mut w).and_then(|()| w.flush()).and_then(|()| std::fs::rename(&tmp, path));
    if let Err(e) = done {
        let _ = std::fs::remove_file(&tmp);
        return Err(io(e));
    }
    Ok(())
}

pub mod generation;

#[cfg(test)]
mod tests;
