//! Link setup for the bare-metal binaries (knurling app-template / embassy examples layout).
//!
//! For the bare-metal target only. The two binaries get different linker scripts:
//! - `firmware` (the board application): cortex-m-rt's `link.x`, which includes a file
//!   named `memory.x`: the STM32G474RE's, at the repository (workspace) root, as the design
//!   card has it. rustc runs the linker in the workspace root, where lld finds it first;
//!   the root is also put on this binary's search path (flip-link reads `-L` folders when
//!   it looks for RAM, and a build run from elsewhere still finds it).
//! - `budget` (the cycle/stack bench run by `hil-sim budget` on QEMU's `mps2-an386`): its
//!   own complete script, `budget-link.x` in this crate (cortex-m-rt's `link.x` with the
//!   machine's MEMORY block in place of `INCLUDE memory.x`), so it never picks up the
//!   board's `memory.x` at the root.
//!
//! Per-binary link arguments, not `rustc-link-search`, which would apply to both. Both
//! get `defmt.x` and `--nmagic`. Host builds (the stub `main`s) get nothing.

use std::{env, path::PathBuf};

fn main() {
    let manifest = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    let root = manifest.parent().expect("firmware/ sits in the workspace root").to_path_buf();
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed={}", root.join("memory.x").display());
    println!("cargo:rerun-if-changed=budget-link.x");

    // Same condition as the `[target.'cfg(target_os = "none")'.dependencies]` table.
    if env::var("CARGO_CFG_TARGET_OS").as_deref() != Ok("none") {
        return;
    }
    assert!(root.join("memory.x").is_file(), "the board's memory.x must be at the repository root");

    // Two arguments (`-L`, folder): flip-link only reads that form when it looks for RAM.
    println!("cargo:rustc-link-arg-bin=firmware=-L");
    println!("cargo:rustc-link-arg-bin=firmware={}", root.display());
    println!("cargo:rustc-link-arg-bin=firmware=-Tlink.x");
    println!("cargo:rustc-link-arg-bin=budget=-L");
    println!("cargo:rustc-link-arg-bin=budget={}", manifest.display());
    println!("cargo:rustc-link-arg-bin=budget=-Tbudget-link.x");

    println!("cargo:rustc-link-arg-bins=--nmagic");
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}
