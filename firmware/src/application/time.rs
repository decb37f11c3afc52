//! Periodic wake-ups and timeouts on a [`Clock`], and a yield to the other tasks.

use core::future::Future;

use embassy_futures::select::{select, Either};

use super::ports::Clock;

/// Wakes every `period_us`, on a fixed grid from its creation (a late wake-up does not
/// shift the next one).
pub struct Ticker {
    next_us: u64,
    period_us: u64,
}

impl Ticker {
    pub fn every(clock: &impl Clock, period_us: u64) -> Self {
        let period_us = period_us.max(1);
        Self { next_us: clock.now_us() + period_us, period_us }
    }

    /// The next tick (at once if it is already past).
    pub async fn next(&mut self, clock: &impl Clock) {
        clock.at(self.next_us).await;
        self.next_us += self.period_us;
    }
}

/// `fut`'s output, or `None` when `timeout_us` passed first.
pub async fn with_timeout<F: Future>(clock: &impl Clock, timeout_us: u64, fut: F) -> Option<F::Output> {
    match select(fut, clock.at(clock.now_us() + timeout_us)).await {
        Either::First(o) => Some(o),
        Either::Second(()) => None,
    }
}

/// Wait `us`.
pub async fn after(clock: &impl Clock, us: u64) {
    clock.at(clock.now_us() + us).await;
}

/// Let the executor run the other tasks once, then go on: what a long computation awaits
/// between chunks so the watchdog task, the other link and the telemetry keep running. A
/// wait on the [`Clock`] cannot stand in for it: one already due (`after(clock, 0)`)
/// resolves at its first poll without giving the executor back.
pub async fn yield_now() {
    embassy_futures::yield_now().await;
}
