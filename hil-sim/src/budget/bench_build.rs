//! The bench ELF (`firmware/src/bin/budget.rs`) and the shipping firmware ELF beside it
//! (`firmware`, for [`isr`](super::isr)): built by cargo with the shipping flags (release
//! profile, fat LTO, `thumbv7em-none-eabihf`).

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use super::error::BudgetError;

/// Build the bench and the firmware with the shipping flags; returns the bench's ELF (the
/// firmware's is [`firmware_elf`] of it).
pub fn build_bench(workspace: &Path) -> Result<PathBuf, BudgetError> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let status = Command::new(cargo)
        .current_dir(workspace)
        .args([
            "build",
            "--release",
            "-p",
            "firmware",
            "--target",
            "thumbv7em-none-eabihf",
            "--bin",
            "budget",
            "--bin",
            "firmware",
        ])
        .stdout(Stdio::null())
        .status()
        .map_err(BudgetError::io("running cargo to build the bench"))?;
    if !status.success() {
        return Err(BudgetError::BuildFailed);
    }
    let target = std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| workspace.join("target"), PathBuf::from);
    Ok(target.join("thumbv7em-none-eabihf/release/budget"))
}

/// The workspace this binary was built from.
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().map_or_else(|| PathBuf::from("."), Path::to_path_buf)
}

/// The shipping firmware ELF built beside a bench ELF.
pub fn firmware_elf(bench: &Path) -> PathBuf {
    bench.with_file_name("firmware")
}
