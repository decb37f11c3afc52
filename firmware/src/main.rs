//! Firmware of the MR clutch torque controller on the STM32G474RE.
//!
//! Built for `thumbv7em-none-eabihf` this is the embassy application in [`app`]. Built
//! for the host (as part of `cargo build/test/clippy --workspace`) it is a stub `main`
//! that only says so; all embedded dependencies are target-gated in Cargo.toml.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod app;

#[cfg(not(target_os = "none"))]
fn main() {
    println!(
        "firmware: this binary only runs on the STM32G474RE board; build it with \
         `cargo build --release -p firmware --target thumbv7em-none-eabihf` \
         (or `cargo run --release` inside firmware/ with a probe attached)"
    );
}
