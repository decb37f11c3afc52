//! Firmware of the MR clutch torque controller on the STM32G474RE.
//!
//! Built for `thumbv7em-none-eabihf` this is the embassy application in `app`: the
//! board's pins and analog scales (`board`), the 20 kHz control interrupt that runs
//! `model_core::control::ControlStep` verbatim (`controller`), and the safe state on
//! panics and faults (`safety`). Built for the host (as part of
//! `cargo build/test/clippy --workspace`) it is a stub `main` that only says so; all
//! embedded dependencies are target-gated in Cargo.toml, and every piece of logic the
//! firmware needs (control step, configuration page, command protocol) lives in model-core,
//! where it is tested on the host.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod app;
#[cfg(target_os = "none")]
mod board;
#[cfg(target_os = "none")]
mod controller;
#[cfg(target_os = "none")]
mod safety;

#[cfg(not(target_os = "none"))]
fn main() {
    println!(
        "firmware: this binary only runs on the STM32G474RE board; build it with \
         `cargo build --release -p firmware --target thumbv7em-none-eabihf` \
         (or `cargo run --release` inside firmware/ with a probe attached)"
    );
}
