//! Why a measurement failed (values, no command-line flags).

use std::num::ParseIntError;
use std::path::PathBuf;

use thiserror::Error;

/// Why a measurement failed.
#[derive(Debug, Error)]
pub enum BudgetError {
    #[error("bench output: malformed line `{line}`")]
    MalformedLine { line: String },
    #[error("bench output: bad address in `{line}`")]
    BadAddress { line: String, source: ParseIntError },
    #[error("bench output: bad call count in `{line}`")]
    BadCalls { line: String, source: ParseIntError },
    /// The bench printed an `error …` line.
    #[error("the bench failed: {line}")]
    BenchReported { line: String },
    #[error("the bench did not finish (no `done` line in its output)")]
    Unfinished,
    #[error("the bench printed no `step` line")]
    NoSteps,
    /// A tool could not be started or read (`what` says which, e.g. `running qemu-system-arm`).
    #[error("{what}")]
    Io { what: String, source: std::io::Error },
    #[error("{tool} not found; {hint}")]
    ToolMissing { tool: &'static str, hint: &'static str },
    #[error("{tool} failed on {}: {stderr}", elf.display())]
    ToolFailed { tool: String, elf: PathBuf, stderr: String },
    #[error("cannot read QEMU's version from `{text}`")]
    QemuVersion { text: String },
    #[error("building the bench (firmware/src/bin/budget.rs) failed")]
    BuildFailed,
    #[error("{}: no such file", .0.display())]
    NoElf(PathBuf),
    #[error("the bench failed on QEMU ({status}): {stdout} {stderr}")]
    BenchFailed { status: String, stdout: String, stderr: String },
    #[error("QEMU's log pipe")]
    NoLogPipe,
    #[error("the firmware ELF has no symbol `{0}`")]
    NoSymbol(String),
    #[error("the traced bench run failed on QEMU ({status})")]
    TracedRunFailed { status: String },
    #[error("the trace ended inside a measured call")]
    TraceEndedInCall,
    #[error("{name}: traced {traced} calls, the bench made {made}")]
    CallsMismatch { name: String, traced: u64, made: u64 },
}

impl BudgetError {
    /// An I/O error while `what` (`running …`, `reading …`).
    pub(crate) fn io(what: impl Into<String>) -> impl FnOnce(std::io::Error) -> Self {
        let what = what.into();
        move |source| Self::Io { what, source }
    }
}
