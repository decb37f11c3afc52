//! The library's [`Progress`] drawn as an indicatif bar on stderr (hidden when stderr is
//! not a terminal; indicatif handles that).

use hil_sim::progress::Progress;
use indicatif::{ProgressBar, ProgressStyle};

/// A progress bar the library advances.
pub struct Bar(ProgressBar);

impl Bar {
    pub fn new(len: u64, what: &str) -> Self {
        let pb = ProgressBar::new(len);
        pb.set_style(
            ProgressStyle::with_template("{msg:>12} [{bar:40}] {pos}/{len} {elapsed_precise}")
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
        pb.set_message(what.to_owned());
        Self(pb)
    }

    /// Remove the bar from the terminal.
    pub fn finish(&self) {
        self.0.finish_and_clear();
    }
}

impl Progress for Bar {
    fn stage(&self, name: &str, total: u64) {
        if total > 0 {
            self.0.set_length(total);
        }
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

impl Drop for Bar {
    fn drop(&mut self) {
        self.0.finish_and_clear();
    }
}
