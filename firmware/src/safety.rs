//! Every way the program can stop drives the H-bridge to its safe state first (the main
//! output enable off: every switch off, the coil de-energises through the diodes), then
//! reports over defmt (non-blocking RTT: a full buffer drops, never waits) and stops where
//! probe-rs shows the backtrace, until the watchdog resets the chip.
//!
//! - Rust panics: the panic handler (panic-probe would print first).
//! - `defmt::panic!`/`unwrap!` inside the HAL print their message before reaching
//!   [`defmt_panic`]; the application itself never uses them ([`fatal`] instead), and the
//!   print cannot block.
//! - HardFault, NMI (a flash ECC double error outside a guarded slot read, the clock
//!   security system) and every interrupt without a handler (`DefaultHandler`).

use core::panic::PanicInfo;
use core::sync::atomic::{AtomicBool, Ordering};

use cortex_m_rt::{exception, ExceptionFrame};

use crate::board::{self, flash};

/// Bridge off, then the message, then a permanent fault (as panic-probe).
pub fn fatal(what: &'static str) -> ! {
    board::safe_state();
    defmt::error!("fatal: {}", what);
    cortex_m::asm::udf()
}

#[panic_handler]
fn panic(info: &PanicInfo) -> ! {
    board::safe_state();
    cortex_m::interrupt::disable();
    static PANICKED: AtomicBool = AtomicBool::new(false);
    if !PANICKED.swap(true, Ordering::Relaxed) {
        defmt::error!("panic: {}", defmt::Display2Format(info));
    }
    // As panic-probe: a permanent UDF fault, which probe-rs reports with a backtrace.
    cortex_m::asm::udf()
}

#[exception]
unsafe fn HardFault(_frame: &ExceptionFrame) -> ! {
    board::safe_state();
    loop {
        cortex_m::asm::bkpt();
    }
}

/// A double ECC error while reading a configuration slot returns (the slot is unusable);
/// anything else stops with the bridge off.
#[exception]
unsafe fn NonMaskableInt() {
    if flash::take_ecc_error() {
        return;
    }
    board::safe_state();
    loop {
        cortex_m::asm::nop();
    }
}

#[exception]
unsafe fn DefaultHandler(_irqn: i16) {
    board::safe_state();
    loop {
        cortex_m::asm::nop();
    }
}

/// Defmt's own panics (`defmt::panic!`) end the same way.
#[defmt::panic_handler]
fn defmt_panic() -> ! {
    board::safe_state();
    cortex_m::asm::udf()
}
