//! Panics and hard faults drive the H-bridge to its safe state before anything else (the
//! main output enable off: every switch off, the coil de-energises through the diodes),
//! then report over defmt and stop where probe-rs shows the backtrace.
//!
//! This replaces panic-probe's handler, which would print first: printing can take a
//! while with the bridge still switching at the last duty.

use core::panic::PanicInfo;
use core::sync::atomic::{AtomicBool, Ordering};

use cortex_m_rt::{exception, ExceptionFrame};

use crate::controller::safe_state;

#[panic_handler]
fn panic(info: &PanicInfo) -> ! {
    safe_state();
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
    safe_state();
    loop {
        cortex_m::asm::bkpt();
    }
}

/// Defmt's own panics (`defmt::panic!`) end the same way.
#[defmt::panic_handler]
fn defmt_panic() -> ! {
    safe_state();
    cortex_m::asm::udf()
}
