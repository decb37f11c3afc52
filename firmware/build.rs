//! Link setup for the board build (knurling app-template / embassy examples layout).
//!
//! For the bare-metal target only: put the workspace's `memory.x` (STM32G474RE) on the
//! linker search path for cortex-m-rt's `link.x`, and pass `link.x`, `defmt.x` and
//! `--nmagic` to the firmware binary. Host builds (the stub `main`) get nothing.

use std::{env, fs, path::PathBuf};

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=../memory.x");

    // Same condition as the `[target.'cfg(target_os = "none")'.dependencies]` table.
    if env::var("CARGO_CFG_TARGET_OS").as_deref() != Ok("none") {
        return;
    }

    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let manifest = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    fs::copy(manifest.join("../memory.x"), out.join("memory.x")).expect("copy ../memory.x into OUT_DIR");
    println!("cargo:rustc-link-search={}", out.display());

    println!("cargo:rustc-link-arg-bins=--nmagic");
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}
