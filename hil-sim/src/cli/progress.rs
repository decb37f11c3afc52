//! The terminal's progress bar ([`indicatif`]) as the library's [`Progress`].

use hil_sim::progress::Progress;

/// Draws a library function's progress on an [`indicatif::ProgressBar`]: a stage sets the
/// bar's length and message, a message replaces the bar's message.
pub struct ProgressBarAdapter(pub indicatif::ProgressBar);

impl ProgressBarAdapter {
    /// A bar styled as every command's ([`super::progress()`]), showing `what`.
    pub fn new(what: &str) -> Self {
        Self(super::progress(1, what))
    }
    /// Remove the bar from the terminal.
    pub fn finish(&self) {
        self.0.finish_and_clear();
    }
}

impl Progress for ProgressBarAdapter {
    fn stage(&self, name: &str, total: u64) {
        self.0.set_length(total);
        self.0.set_position(0);
        self.0.set_message(name.to_owned());
    }
    fn advance(&self, n: u64) {
        self.0.inc(n);
    }
    fn message(&self, msg: &str) {
        self.0.set_message(msg.to_owned());
    }
}
