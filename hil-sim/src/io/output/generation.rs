//! A folder written as one generation: its files are written into a fresh folder beside it
//! (`.NAME.new-PID`) and swapped in whole when they are all there, so the folder always holds
//! one save's files, never a mix of two; a second writer is refused while the first holds
//! the folder's lock (`.NAME.lock`, an advisory `flock` the system releases when the process
//! dies); and a save interrupted at any point leaves the old folder as it was (its leftover
//! staging folder is removed by the next save).
//!
//! The swap replaces the whole folder, so it only replaces a folder a previous generation
//! wrote (it holds [`MARKER`]) or an empty one: files of the user's are never thrown away.

use std::fs::File;
use std::path::{Path, PathBuf};

use thiserror::Error;

use super::OutputError;

/// The file each generation carries: what wrote it.
pub const MARKER: &str = ".hil-sim-generation";

#[derive(Debug, Error)]
pub enum GenerationError {
    #[error("{path}: another hil-sim is writing this folder now (it holds {lock}); try again when it is done")]
    Busy { path: PathBuf, lock: PathBuf },
    #[error(
        "{path}: holds files hil-sim did not write (`{example}`, …); a save replaces the whole folder, so \
         choose a new or empty one"
    )]
    Foreign { path: PathBuf, example: String },
    #[error("{path}: exists and is not a folder")]
    NotFolder { path: PathBuf },
    #[error(transparent)]
    Output(#[from] OutputError),
    #[error("{path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
}

/// A generation being written; see the module docs.
#[derive(Debug)]
pub struct Generation {
    target: PathBuf,
    staging: PathBuf,
    _lock: File,
    committed: bool,
}

impl Generation {
    /// Take `target`'s lock and open a fresh staging folder for it.
    pub fn begin(target: &Path) -> Result<Self, GenerationError> {
        super::check(target)?;
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| GenerationError::Io { path, source }
        };
        let parent = target.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
        super::create_dir(parent)?;
        let name = target.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| ".".into());
        let lock_path = parent.join(format!(".{name}.lock"));
        let lock = std::fs::OpenOptions::new()
            .create(true)
            .truncate(false)
            .write(true)
            .open(&lock_path)
            .map_err(io(&lock_path))?;
        if !try_lock(&lock) {
            return Err(GenerationError::Busy { path: target.to_path_buf(), lock: lock_path });
        }
        // Holding the lock, any staging folder is a leftover of an interrupted save.
        let prefix = format!(".{name}.new-");
        for e in std::fs::read_dir(parent).map_err(io(parent))?.flatten() {
            if e.file_name().to_string_lossy().starts_with(&prefix) {
                let _ = std::fs::remove_dir_all(e.path());
            }
        }
        match std::fs::symlink_metadata(target) {
            Ok(m) if !m.is_dir() => return Err(GenerationError::NotFolder { path: target.to_path_buf() }),
            Ok(_) if !target.join(MARKER).exists() => {
                if let Some(e) = std::fs::read_dir(target).map_err(io(target))?.flatten().next() {
                    let example = e.file_name().to_string_lossy().chars().take(40).collect();
                    return Err(GenerationError::Foreign { path: target.to_path_buf(), example });
                }
            }
            _ => {}
        }
        let staging = parent.join(format!("{prefix}{}", std::process::id()));
        std::fs::create_dir(&staging).map_err(io(&staging))?;
        Ok(Self { target: target.to_path_buf(), staging, _lock: lock, committed: false })
    }

    /// Where this generation's files are written.
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// Swap the generation in whole (`what` is recorded in its [`MARKER`]).
    pub fn commit(mut self, what: &str) -> Result<(), GenerationError> {
        super::write(&self.staging.join(MARKER), format!("{what}\n"))?;
        let io = |source| GenerationError::Io { path: self.target.clone(), source };
        if std::fs::symlink_metadata(&self.target).is_ok() {
            if !exchange(&self.staging, &self.target) {
                // Without an atomic exchange: aside, in, then the old one removed.
                let old = self.staging.with_extension("old");
                std::fs::rename(&self.target, &old).map_err(io)?;
                std::fs::rename(&self.staging, &self.target).map_err(io)?;
                let _ = std::fs::remove_dir_all(&old);
                self.committed = true;
                return Ok(());
            }
            // The old generation is now at the staging path.
            let _ = std::fs::remove_dir_all(&self.staging);
        } else {
            std::fs::rename(&self.staging, &self.target).map_err(io)?;
        }
        self.committed = true;
        Ok(())
    }
}

impl Drop for Generation {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_dir_all(&self.staging);
        }
    }
}

#[cfg(unix)]
fn try_lock(f: &File) -> bool {
    use std::os::unix::io::AsRawFd;
    // SAFETY: flock on a descriptor this process owns; no memory is involved.
    unsafe { libc::flock(f.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) == 0 }
}

#[cfg(not(unix))]
fn try_lock(_: &File) -> bool {
    true
}

/// Swap two paths atomically (Linux `renameat2(RENAME_EXCHANGE)`); false where it is not
/// available.
#[cfg(target_os = "linux")]
fn exchange(a: &Path, b: &Path) -> bool {
    use std::os::unix::ffi::OsStrExt;
    let (Ok(a), Ok(b)) =
        (std::ffi::CString::new(a.as_os_str().as_bytes()), std::ffi::CString::new(b.as_os_str().as_bytes()))
    else {
        return false;
    };
    // SAFETY: two NUL-terminated paths that live across the call.
    unsafe { libc::renameat2(libc::AT_FDCWD, a.as_ptr(), libc::AT_FDCWD, b.as_ptr(), libc::RENAME_EXCHANGE) == 0 }
}

#[cfg(not(target_os = "linux"))]
fn exchange(_: &Path, _: &Path) -> bool {
    false
}
