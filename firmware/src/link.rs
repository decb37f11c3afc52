//! The command link's timeout: the host must send a command (any valid frame to the
//! command identifier; the torque set-point is streamed) at least every `timeout_ms`
//! while the drive is enabled. When it stops, the drive is disabled and the reference
//! zeroed (the clutch releases rather than holding the last reference forever). A later
//! `Enable` command re-arms it.

/// Tracks when the host was last heard.
/// The host must be heard this often while the drive is enabled, ms.
pub const COMMAND_TIMEOUT_MS: u64 = 100;

#[derive(Clone, Copy, Debug)]
pub struct LinkWatch {
    timeout_ms: u64,
    last_ms: u64,
}

/// What the command task must do now.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LinkAction {
    None,
    /// Disable the drive and zero the reference: the host has been silent too long.
    Release,
}

impl LinkWatch {
    pub const fn new(timeout_ms: u64, now_ms: u64) -> Self {
        Self { timeout_ms, last_ms: now_ms }
    }

    /// A valid command arrived.
    pub fn heard(&mut self, now_ms: u64) {
        self.last_ms = now_ms;
    }

    /// Called on every wake-up of the command task (frame or timeout); `enabled` is the
    /// drive enable as it stands.
    pub fn poll(&mut self, now_ms: u64, enabled: bool) -> LinkAction {
        if enabled && now_ms.saturating_sub(self.last_ms) > self.timeout_ms {
            self.last_ms = now_ms;
            LinkAction::Release
        } else {
            LinkAction::None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn silence_while_enabled_releases_once_per_timeout() {
        let mut w = LinkWatch::new(100, 0);
        assert_eq!(w.poll(50, true), LinkAction::None);
        w.heard(90);
        assert_eq!(w.poll(190, true), LinkAction::None, "exactly the timeout is still fine");
        assert_eq!(w.poll(191, true), LinkAction::Release);
        assert_eq!(w.poll(192, true), LinkAction::None, "not again at once");
    }

    #[test]
    fn silence_while_disabled_is_fine() {
        let mut w = LinkWatch::new(100, 0);
        assert_eq!(w.poll(10_000, false), LinkAction::None);
    }
}
