//! The supervisor task: asks for the slow pass of the control step (configuration
//! fingerprint, time step, temperature compensation) at [`SLOW_HZ`]; the control interrupt
//! runs it after its next compare write, and trips `SupervisorStalled` if this task stops.

use super::ports::{Clock, ControlPort};
use super::time::Ticker;
use super::App;

/// Rate of the slow supervisor pass, Hz (the step trips `SupervisorStalled` after 0.1 s
/// without one).
pub const SLOW_HZ: u64 = 1_000;

pub async fn run<C: Clock, F, P: ControlPort, E>(app: App<'_, C, F, P, E>) -> ! {
    let mut ticker = Ticker::every(app.clock, 1_000_000 / SLOW_HZ);
    loop {
        ticker.next(app.clock).await;
        app.ctl.request_slow_pass();
    }
}
