//! Link setup for the bare-metal binaries (knurling app-template / embassy examples layout).
//!
//! For the bare-metal target only. cortex-m-rt's `link.x` includes a file named `memory.x`
//! from the linker search path; the two binaries need different ones, so each gets its own
//! folder on its own search path (per-binary link arguments, not `rustc-link-search`,
//! which would apply to both):
//! - `firmware` (the board application): `memory.x` (STM32G474RE);
//! - `budget` (the cycle/stack bench run by `hil-sim budget` on QEMU's `mps2-an386`):
//!   `budget-memory.x`.
//!
//! The files live in this crate, not at the workspace root: rustc runs the linker in the
//! workspace root, and lld takes a `memory.x` found there before any search path.
//!
//! Both get `link.x`, `defmt.x` and `--nmagic`. Host builds (the stub `main`s) get nothing.

use std::{env, fs, path::PathBuf};

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=budget-memory.x");

    // Same condition as the `[target.'cfg(target_os = "none")'.dependencies]` table.
    if env::var("CARGO_CFG_TARGET_OS").as_deref() != Ok("none") {
        return;
    }

    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let manifest = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    for (bin, src) in [("firmware", manifest.join("memory.x")), ("budget", manifest.join("budget-memory.x"))] {
        let dir = out.join(bin);
        fs::create_dir_all(&dir).expect("create a linker-script folder in OUT_DIR");
        fs::copy(&src, dir.join("memory.x")).unwrap_or_else(|e| panic!("copy {}: {e}", src.display()));
        // Two arguments (`-L`, folder): flip-link only reads that form when it looks for RAM.
        println!("cargo:rustc-link-arg-bin={bin}=-L");
        println!("cargo:rustc-link-arg-bin={bin}={}", dir.display());
    }

    println!("cargo:rustc-link-arg-bins=--nmagic");
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}
