//! The external tools: `qemu-system-arm` (on the PATH) and `llvm-objdump` (rustup's
//! `llvm-tools` or the PATH), QEMU's version, and the disassembly of the bench ELF.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use super::cycles::{parse_disassembly, Cycles};
use super::error::BudgetError;

/// Address → cycle bounds of every instruction in the ELF (`llvm-objdump -d`).
pub fn disassemble(objdump: &Path, elf: &Path) -> Result<HashMap<u32, Cycles>, BudgetError> {
    let out = Command::new(objdump)
        .args(["-d", "--no-show-raw-insn"])
        .arg(elf)
        .output()
        .map_err(BudgetError::io(format!("running {}", objdump.display())))?;
    if !out.status.success() {
        return Err(BudgetError::ToolFailed {
            tool: objdump.display().to_string(),
            elf: elf.to_path_buf(),
            stderr: String::from_utf8_lossy(&out.stderr).trim().to_owned(),
        });
    }
    Ok(parse_disassembly(&String::from_utf8_lossy(&out.stdout)))
}

/// Where the tools are.
#[derive(Clone, Debug)]
pub struct Tools {
    pub qemu: PathBuf,
    pub objdump: PathBuf,
}

fn on_path(name: &str) -> Option<PathBuf> {
    std::env::var_os("PATH").and_then(|p| std::env::split_paths(&p).map(|d| d.join(name)).find(|p| p.is_file()))
}

impl Tools {
    /// `qemu-system-arm` on the PATH; `llvm-objdump` from rustup's `llvm-tools` (the
    /// toolchain's sysroot) or the PATH.
    pub fn find() -> Result<Self, BudgetError> {
        let qemu = on_path("qemu-system-arm").ok_or(BudgetError::ToolMissing {
            tool: "qemu-system-arm",
            hint: "`scripts/setup` installs it (Debian: apt-get install qemu-system-arm)",
        })?;
        let sysroot_objdump = Command::new("rustc").args(["--print", "sysroot"]).output().ok().and_then(|o| {
            let root = PathBuf::from(String::from_utf8_lossy(&o.stdout).trim());
            std::fs::read_dir(root.join("lib/rustlib"))
                .ok()?
                .filter_map(Result::ok)
                .map(|e| e.path().join("bin/llvm-objdump"))
                .find(|p| p.is_file())
        });
        let objdump = sysroot_objdump.or_else(|| on_path("llvm-objdump")).ok_or(BudgetError::ToolMissing {
            tool: "llvm-objdump",
            hint: "`rustup component add llvm-tools` (scripts/setup does) or install LLVM",
        })?;
        Ok(Self { qemu, objdump })
    }

    /// QEMU's version `(major, minor)` (the flag for one instruction per block changed in 8.1).
    pub fn qemu_version(&self) -> Result<(u32, u32), BudgetError> {
        let out = Command::new(&self.qemu)
            .arg("--version")
            .output()
            .map_err(BudgetError::io("running qemu-system-arm --version"))?;
        let text = String::from_utf8_lossy(&out.stdout);
        parse_qemu_version(&text).ok_or_else(|| BudgetError::QemuVersion { text: text.trim().to_owned() })
    }

    /// QEMU on the Cortex-M4F machine with `elf` as its kernel, no monitor or serial.
    pub fn qemu_cmd(&self, elf: &Path) -> Command {
        let mut cmd = Command::new(&self.qemu);
        cmd.args(["-M", "mps2-an386", "-cpu", "cortex-m4", "-nographic", "-monitor", "none", "-serial", "none"])
            .arg("-kernel")
            .arg(elf)
            .stdin(Stdio::null());
        cmd
    }
}

/// `(major, minor)` from `QEMU emulator version 7.2.22 (Debian …)`.
fn parse_qemu_version(text: &str) -> Option<(u32, u32)> {
    let v = text.split_whitespace().skip_while(|w| *w != "version").nth(1)?;
    let mut it = v.split('.');
    Some((it.next()?.parse().ok()?, it.next()?.parse().ok()?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn qemu_versions() {
        assert_eq!(parse_qemu_version("QEMU emulator version 7.2.22 (Debian 1:7.2+dfsg-7)\n"), Some((7, 2)));
        assert_eq!(parse_qemu_version("QEMU emulator version 8.1.0\n"), Some((8, 1)));
        assert_eq!(parse_qemu_version("nonsense"), None);
    }
}
