//! The one table of targets: instructions per call and stack bytes for each measured step
//! (model steps by their model's `ID`, the control step and the slow supervisor pass), and
//! the firmware's control rate and core clock (Hz) for the CPU-load figure.

use model_core::models::{algebraic, bouc_wen, lugre, narx, tanh};
use model_core::Model;
use serde::Serialize;

/// A step's target: at most this many instructions per call (the worst call of the sweep)
/// and this many bytes of stack.
///
/// `ceiling_*` is what the check (`hil-sim budget --check`, and so CI) enforces. It equals the target for every step
/// that meets it. A step that does not meet its target yet gets a ceiling just above what
/// it measures today, so CI still catches a regression; the table and the JSON report it
/// against its target (`OVER`, `within_budget: false`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Budget {
    pub name: &'static str,
    pub instructions: u64,
    pub stack_bytes: u32,
    pub ceiling_instructions: u64,
    pub ceiling_stack_bytes: u32,
}

impl Budget {
    const fn met(name: &'static str, instructions: u64, stack_bytes: u32) -> Self {
        Self { name, instructions, stack_bytes, ceiling_instructions: instructions, ceiling_stack_bytes: stack_bytes }
    }

    /// A met target for the step of model `M` (named by its `M::ID`).
    pub const fn met_model<M: Model>(instructions: u64, stack_bytes: u32) -> Self {
        Self::met(M::ID, instructions, stack_bytes)
    }
}

/// The budgets (issue "Firmware for the STM32 clutch driver board"): close to what
/// hand-minimal kernels measured on this machine; `control_step` at 20 kHz stays under 5 %
/// of the 170 MHz core. Steps not listed are measured and reported, without a target.
pub const BUDGETS: [Budget; 7] = [
    Budget::met_model::<algebraic::Registered>(30, 16),
    Budget::met_model::<bouc_wen::Registered>(45, 16),
    Budget::met_model::<tanh::Registered>(80, 64),
    Budget::met_model::<lugre::Registered>(50, 24),
    // The board's NARX (8 sigmoid units, 86 values; issue 7): 771 instructions / 160 B
    // measured on 2026-11-22 (seed 000's 71-unit net: 6031 / 136 B).
    Budget::met_model::<narx::Registered>(800, 160),
    // 288 instructions / 112 B measured on 2026-11-23 (1010 before the redesign, 423 before
    // the slow-developing supervisor checks moved to the slow pass, 355 before the
    // feed-forward's linearisation moved there and the torque loop went to half rate).
    Budget::met("control_step", 300, 128),
    // The slow supervisor pass (`ControlStep::slow`, 1 kHz, requested by a thread-mode task
    // and run in the control interrupt's tail since 2026-11-24, issue 19): configuration fingerprint, coefficients, time step, the feed-forward's
    // linearisation, and since 2026-11-22 the slow-developing checks (Hall noise, stuck
    // Hall, coil open, B/i band) replayed over the ≤ 20 samples logged since the previous
    // pass (~85 instructions a sample; 2,847 / 344 B measured on 2026-11-23). Raised from
    // 1,200 / 320 B: 3,000 instructions at 1 kHz are ~2.5 % of the 170 MHz core.
    Budget::met("supervisor_slow", 3000, 352),
];

/// Control-step rate and core clock of the firmware, for the CPU-load figure.
pub const CONTROL_HZ: f64 = 20_000.0;
pub const CORE_HZ: f64 = 170.0e6;
