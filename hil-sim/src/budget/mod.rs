//! Instructions, cycles and stack of every model step and of the control step on the
//! Cortex-M4F, for the shipping build flags (`hil-sim budget`).
//!
//! Method: the bench binary `firmware/src/bin/budget.rs` (release profile, fat LTO,
//! `thumbv7em-none-eabihf`) runs on QEMU's `mps2-an386` machine (a Cortex-M4 with FPU).
//! It calls each step through an opaque function pointer over an input sweep and prints,
//! by semihosting, `step <name> <address> <calls>` before each sweep. A first run without
//! tracing collects those lines; a second run with `-singlestep -d exec,cpu,nochain`
//! (QEMU ≥ 8.1: `-accel tcg,one-insn-per-tb=on`) logs PC and registers before every
//! instruction, streamed through a pipe into [`Tracer`], which counts for every call the
//! instructions from the entry of the measured function to the return to its caller
//! (`pc == lr` with the entry SP), and the lowest SP in between (stack bytes = entry SP −
//! lowest SP; what the step needs beyond its caller's frame).
//!
//! Cycles: each executed instruction is classified from the ELF's disassembly
//! (`llvm-objdump`) with the Cortex-M4 timings (ARM DDI 0439 §3.3, FPU: DDI 0439 §7.2):
//! most data processing 1; LDR/STR 1–2 (a load or store next to another one pipelines to
//! 1); LDRD/STRD 2–3; LDM/STM/PUSH/POP and VLDM/VSTM/VPUSH/VPOP 1 + registers (+ 1–3 with
//! PC); branches 1–4 (not taken 1; taken 1 + a pipeline refill of 1–3); BL/BX/BLX 2–4;
//! MLA/MLS 2; SDIV/UDIV 2–12; VLDR/VSTR 1–2; VMLA/VMLS/VFMA… 3; VDIV/VSQRT 14; IT 0–1.
//! Flash wait states are not modelled (the G474 runs from its ART accelerator/cache; code
//! in CCM SRAM would have none). A step's range is the largest lower bound and the largest
//! upper bound over its calls.
//!
//! [`BUDGETS`] is the one table of targets; `hil-sim budget --check` fails naming the step
//! that exceeds one.
//!
//! The shipping firmware ELF, built beside the bench, is read statically ([`isr`]): the
//! control interrupt's call graph as built (no f64 soft-float helper may be reachable from
//! it, and it may not mask interrupts: the deadline monitor must pre-empt it), and the
//! longest interrupt-masked stretch in the interrupts' code and in thread mode. The slow supervisor pass runs in the
//! control interrupt's tail (after the compare write), so the interrupt's worst case is
//! `control_step` + `supervisor_slow`, checked against one control period.
//!
//! Modules: [`table`](mod@table) (the targets), [`cycles`] (instruction classes),
//! [`trace`] (bench output and QEMU log), [`figures`] (per-step figures, the report and its
//! table), [`tools`] (QEMU, llvm-objdump), [`bench_build`] (cargo build of the bench),
//! [`measure`](mod@measure) (the runs on QEMU), [`isr`] (the firmware's interrupts as
//! built), [`error`] (why a measurement failed).

pub mod bench_build;
pub mod cycles;
pub mod error;
pub mod figures;
pub mod isr;
pub mod measure;
pub mod table;
pub mod tools;
pub mod trace;

pub use bench_build::{build_bench, firmware_elf, workspace_root};
pub use cycles::{cycles_of, parse_disassembly, Cycles};
pub use error::BudgetError;
pub use figures::{table, Report, StepFigures};
pub use isr::{Interrupts, Masked, Root};
pub use measure::{measure, run};
pub use table::{Budget, BUDGETS, CONTROL_HZ, CORE_HZ};
pub use tools::{disassemble, Tools};
pub use trace::{parse_markers, Marker, Tracer};
