//! Progress of long library work, reported to whoever called (the CLI draws a bar; tests pass `&NoProgress`).
/// Receives progress from long-running library functions.
pub trait Progress: Sync {
    /// A new stage of `total` steps (0: unknown), e.g. "profiling transforms".
    fn stage(&self, _name: &str, _total: u64) {}
    /// `n` more steps of the current stage are done.
    fn advance(&self, _n: u64) {}
    /// A one-line message for the user (a log line, not an error).
    fn message(&self, _msg: &str) {}
}
/// Discards everything.
pub struct NoProgress;
impl Progress for NoProgress {}
