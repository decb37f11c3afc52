//! The telemetry task: the control interrupt's decimated snapshot to the log at 10 Hz, and
//! missed deadlines reported loudly.

use super::ports::{Clock, ControlPort, Event, Events};
use super::time::Ticker;
use super::App;

/// Log period, µs.
pub const PERIOD_US: u64 = 100_000;

pub async fn run<C: Clock, F, P: ControlPort, E: Events>(app: App<'_, C, F, P, E>) -> ! {
    let mut ticker = Ticker::every(app.clock, PERIOD_US);
    let mut overruns = 0;
    loop {
        ticker.next(app.clock).await;
        app.events.event(Event::Telemetry(app.ctl.snapshot()));
        let now = app.ctl.overruns();
        if now != overruns {
            app.events.event(Event::Overruns(now, now.wrapping_sub(overruns)));
            overruns = now;
        }
    }
}
