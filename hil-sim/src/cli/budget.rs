//! `hil-sim budget`: instructions, cycles and stack per model step and control step on the
//! Cortex-M4F (method in `hil_sim::budget`).

use std::path::PathBuf;

use anyhow::bail;
use clap::Args;
use hil_sim::budget;
use hil_sim::progress::Progress;
use serde_json::json;

#[derive(Args, Debug)]
pub struct BudgetArgs {
    /// A prebuilt bench ELF (`firmware/src/bin/budget.rs` for thumbv7em-none-eabihf,
    /// release). Default: build it with cargo in this workspace.
    #[arg(long)]
    pub elf: Option<PathBuf>,
    /// Exit non-zero, naming the step, when a step exceeds its budget's ceiling (the target,
    /// or for a step that misses its target, the guard just above today's figure).
    #[arg(long)]
    pub check: bool,
    #[arg(long)]
    pub json: bool,
}

/// The library's progress messages as log lines on stderr.
struct Log;

impl Progress for Log {
    fn message(&self, msg: &str) {
        eprintln!("{msg}");
    }
}

pub fn run(a: BudgetArgs) -> anyhow::Result<()> {
    let report = budget::run(a.elf.as_deref(), &Log)?;
    if a.json {
        let rates = report.model_rates();
        let fig = |s: &budget::StepFigures| {
            // A model's control step: its firmware rate and whether it fits there (issue 17).
            let rate = s.name.strip_prefix("control_step_").and_then(|id| rates.iter().find(|r| r.model == id));
            let within = match rate {
                Some(r) => Some(r.fits && s.excess().is_empty()),
                None => s.budget.map(|_| s.excess().is_empty()),
            };
            json!({
                "name": s.name,
                "stack_bytes": s.stack_bytes,
                "instructions": s.instructions,
                "mean_instructions": (s.mean_instructions * 10.0).round() / 10.0,
                "cycles_min": s.cycles_min,
                "cycles_max": s.cycles_max,
                "calls": s.calls,
                "budget": s.budget.map(|b| json!({
                    "instructions": b.instructions, "stack_bytes": b.stack_bytes,
                    "ceiling_instructions": b.ceiling_instructions, "ceiling_stack_bytes": b.ceiling_stack_bytes,
                })),
                "within_budget": within,
                "control_hz": rate.and_then(|r| r.control_hz),
                "slow_cycles": rate.map(|r| r.slow_cycles),
                "cpu_percent": rate.map(|r| (r.cpu_percent * 10.0).round() / 10.0),
                "period_percent": rate.map(|r| (r.period_percent * 10.0).round() / 10.0),
            })
        };
        let steps: Vec<_> = report.steps.iter().filter(|s| !s.outside).map(fig).collect();
        let outside: Vec<_> = report.steps.iter().filter(|s| s.outside).map(fig).collect();
        super::print_json(&json!({
            "machine": report.machine,
            "elf": report.elf,
            "control_hz": budget::CONTROL_HZ,
            "cpu_share_percent": firmware::runner::CPU_SHARE_PERCENT,
            "slow_hz": firmware::runner::SLOW_HZ,
            "core_hz": budget::CORE_HZ,
            "traced_instructions": report.traced_instructions,
            "steps": steps,
            "outside_envelope": outside,
            "interrupts": report.interrupts.as_ref().map(|i| json!({
                "roots": i.roots.iter().map(|r| json!({
                    "name": r.name,
                    "functions": r.call_graph.len(),
                    "call_graph": r.call_graph.iter().map(|(f, c)| json!({"function": f, "calls": c})).collect::<Vec<_>>(),
                    "f64_soft_float": r.f64_soft_float,
                    "masking": r.masking,
                    "indirect_calls": r.indirect_calls,
                })).collect::<Vec<_>>(),
                "isr_with_slow_pass_cycles_max": report.isr_cycles_max(),
                "slow_pass_masked_cycles": i.interrupt_masked.cycles_max,
                "interrupt_masked": i.interrupt_masked,
                "thread_masked": i.thread_masked,
            })),
        }))?;
    } else {
        super::emit(&budget::table(&report));
    }
    let missed = report.exceeded();
    if !missed.is_empty() {
        eprintln!("warning: over target: {}", missed.join("; "));
    }
    let over = report.over_ceiling();
    if a.check && !over.is_empty() {
        bail!("over budget: {}", over.join("; "));
    }
    Ok(())
}
