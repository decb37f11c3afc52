//! A measurement: the bench run untraced on QEMU for its markers, then traced, its log
//! streamed through [`Tracer`]; and [`run`], the whole `hil-sim budget` (tools, build,
//! measurement) as one call.

use std::io::{BufRead, BufReader, Read};
use std::path::Path;
use std::process::Stdio;

use super::bench_build::{build_bench, firmware_elf, workspace_root};
use super::error::BudgetError;
use super::figures::Report;
use super::tools::{disassemble, Tools};
use super::trace::{parse_markers, Tracer};
use crate::progress::Progress;

/// Run the bench ELF on QEMU (untraced for the markers, then traced) and measure.
pub fn measure(tools: &Tools, elf: &Path) -> Result<Report, BudgetError> {
    if !elf.is_file() {
        return Err(BudgetError::NoElf(elf.to_path_buf()));
    }
    let cycles = disassemble(&tools.objdump, elf)?;
    let out = tools
        .qemu_cmd(elf)
        .args(["-semihosting-config", "enable=on,target=native"])
        .stderr(Stdio::piped())
        .output()
        .map_err(BudgetError::io("running qemu-system-arm"))?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    if !out.status.success() {
        return Err(BudgetError::BenchFailed {
            status: out.status.to_string(),
            stdout: stdout.trim().replace('\n', "; "),
            stderr: String::from_utf8_lossy(&out.stderr).trim().replace('\n', "; "),
        });
    }
    let markers = parse_markers(&stdout)?;

    let mut cmd = tools.qemu_cmd(elf);
    if tools.qemu_version()? >= (8, 1) {
        cmd.args(["-accel", "tcg,one-insn-per-tb=on"]);
    } else {
        cmd.arg("-singlestep");
    }
    // The log goes to stdout through QEMU's buffered log file (stderr would be unbuffered:
    // a write per line); the bench's semihosting output goes to a null chardev.
    cmd.args(["-semihosting-config", "enable=on,target=native,chardev=bench", "-chardev", "null,id=bench"])
        .args(["-d", "exec,cpu,nochain", "-D", "/dev/stdout"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null());
    let mut child = cmd.spawn().map_err(BudgetError::io("running qemu-system-arm with tracing"))?;
    let log = child.stdout.take().ok_or(BudgetError::NoLogPipe)?;
    let mut tracer = Tracer::new(&markers, &cycles);
    let mut reader = BufReader::with_capacity(1 << 20, log);
    let mut line = Vec::with_capacity(256);
    loop {
        line.clear();
        let n = reader.read_until(b'\n', &mut line).map_err(BudgetError::io("reading QEMU's log"))?;
        if n == 0 {
            break;
        }
        tracer.line(&line);
    }
    let mut rest = Vec::new();
    let _ = reader.read_to_end(&mut rest);
    let status = child.wait().map_err(BudgetError::io("waiting for QEMU"))?;
    if !status.success() {
        return Err(BudgetError::TracedRunFailed { status: status.to_string() });
    }
    let executed = tracer.executed;
    let steps = tracer.finish()?;
    Ok(Report {
        elf: elf.to_path_buf(),
        machine: "qemu-system-arm -M mps2-an386 -cpu cortex-m4 (Cortex-M4F)",
        steps,
        traced_instructions: executed,
        interrupts: None,
    })
}

/// The whole `hil-sim budget`: find the tools, build the bench and the firmware unless
/// `elf` names a prebuilt bench (the firmware ELF is then expected beside it), measure the
/// bench and read the firmware's interrupts; what it is doing goes to `progress`.
pub fn run(elf: Option<&Path>, progress: &dyn Progress) -> Result<Report, BudgetError> {
    let tools = Tools::find()?;
    let elf = match elf {
        Some(p) => p.to_path_buf(),
        None => {
            progress.message(
                "building the bench and the firmware (cargo build --release -p firmware --target thumbv7em-none-eabihf)",
            );
            build_bench(&workspace_root())?
        }
    };
    progress.message(&format!("tracing {} on QEMU mps2-an386 (a minute or two)", elf.display()));
    let mut report = measure(&tools, &elf)?;
    let firmware = firmware_elf(&elf);
    progress.message(&format!("reading the interrupts of {}", firmware.display()));
    report.interrupts = Some(super::isr::analyse(&tools.objdump, &firmware)?);
    Ok(report)
}
