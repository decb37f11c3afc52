//! Progress of long library work, reported to whoever called (the CLI draws a bar; tests pass `&NoProgress`).

/// Receives progress from long-running library functions.
pub trait Progress: Sync {
    /// A new stage of `total` steps (0: unknown), e.g. "profiling transforms".
    fn stage(&self, _name: &str, _total: u64) {}
    /// `n` more steps of the current stage are done.
    fn advance(&self, _n: u64) {}
    /// What is being done now, one line for the user (not an error): a bar shows it as its
    /// message, a log prints it.
    fn message(&self, _msg: &str) {}
}

/// Discards everything.
pub struct NoProgress;

impl Progress for NoProgress {}
