//! The watchdog task: pets the independent watchdog only while the control interrupt keeps
//! running. A stalled loop gets the bridge off and the stall latched at once, then the
//! watchdog resets the chip (the bridge is off from reset on).

use super::ports::{Clock, ControlPort, Event, Events, Watchdog};
use super::time::Ticker;
use super::App;

/// The independent watchdog's timeout, µs (the board's IWDG; the virtual board models the
/// same).
pub const TIMEOUT_US: u32 = 50_000;

/// How often the control interrupt's progress is checked, µs (well inside the watchdog's
/// timeout).
pub const CHECK_US: u64 = 10_000;

pub async fn run<C: Clock, F, P: ControlPort, E: Events>(app: App<'_, C, F, P, E>, wd: &mut impl Watchdog) -> ! {
    wd.start();
    let mut last = app.ctl.samples();
    let mut ticker = Ticker::every(app.clock, CHECK_US);
    loop {
        ticker.next(app.clock).await;
        let now = app.ctl.samples();
        if now != last && !app.ctl.stalled() {
            wd.pet();
        } else if now == last {
            // Bridge off and the stall latched, so the loop reports it (the mode does not
            // read Running with the bridge off) should the interrupt come back.
            app.ctl.stall();
            app.events.event(Event::Stalled);
        } else {
            // Stalled but sampling again (deadline monitor, damaged configuration): the
            // loop holds the bridge off in its fault; keep the watchdog fed.
            wd.pet();
        }
        last = now;
    }
}
