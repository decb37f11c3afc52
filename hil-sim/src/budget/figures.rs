//! Figures of a measurement: per step the worst call's instructions, the mean, the cycle
//! range and the stack bytes against its [`Budget`]; the whole report and its text table
//! (CPU load of the control step at [`CONTROL_HZ`] on [`CORE_HZ`]).

use std::path::PathBuf;

use serde::Serialize;

use super::isr::{tree, Interrupts, Masked};
use super::table::{Budget, CONTROL_HZ, CORE_HZ};

/// Figures of one measured step.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct StepFigures {
    pub name: String,
    /// Instructions of the worst call.
    pub instructions: u64,
    /// Mean instructions per call over the sweep.
    pub mean_instructions: f64,
    /// Cycle range of the worst case: largest lower bound, largest upper bound.
    pub cycles_min: u64,
    pub cycles_max: u64,
    /// Deepest stack below the entry SP, bytes.
    pub stack_bytes: u32,
    pub calls: u64,
    /// Measured beyond the operating envelope (no budget applies).
    pub outside: bool,
    /// The target, if [`BUDGETS`](super::table::BUDGETS) has one.
    pub budget: Option<Budget>,
}

impl StepFigures {
    /// The reasons this step misses its budget (empty when within, or without one).
    pub fn excess(&self) -> Vec<String> {
        self.budget.map_or_else(Vec::new, |b| self.beyond(b.instructions, b.stack_bytes))
    }

    /// The reasons this step exceeds the ceiling `--check` enforces (empty when within).
    pub fn over_ceiling(&self) -> Vec<String> {
        self.budget.map_or_else(Vec::new, |b| self.beyond(b.ceiling_instructions, b.ceiling_stack_bytes))
    }

    fn beyond(&self, instructions: u64, stack_bytes: u32) -> Vec<String> {
        let mut v = Vec::new();
        if self.instructions > instructions {
            v.push(format!("{} instructions > {instructions}", self.instructions));
        }
        if self.stack_bytes > stack_bytes {
            v.push(format!("{} B of stack > {stack_bytes} B", self.stack_bytes));
        }
        v
    }
}
/// A whole measurement.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    pub elf: PathBuf,
    pub machine: &'static str,
    pub steps: Vec<StepFigures>,
    /// Instructions in the whole trace (bench set-up included).
    pub traced_instructions: u64,
    /// The shipping firmware's interrupts (static, from its ELF).
    pub interrupts: Option<Interrupts>,
}

impl Report {
    /// Steps that miss their budget, with the reasons.
    pub fn exceeded(&self) -> Vec<String> {
        self.named(StepFigures::excess)
    }

    /// Steps over the ceiling `--check` enforces, with the reasons; and what the firmware's
    /// interrupts may not do (reach an f64 soft-float helper, mask interrupts, step + slow
    /// pass beyond a period).
    pub fn over_ceiling(&self) -> Vec<String> {
        let mut v = self.named(StepFigures::over_ceiling);
        if let Some(i) = &self.interrupts {
            v.extend(i.violations());
        }
        if let Some(c) = self.isr_cycles_max() {
            let period = (CORE_HZ / CONTROL_HZ) as u64;
            if c > period {
                v.push(format!("control interrupt with the slow pass: {c} cycles > one period ({period})"));
            }
        }
        v
    }

    /// Worst cycles of the control interrupt on a sample that also runs the slow pass:
    /// `control_step` + `supervisor_slow` (upper bounds).
    pub fn isr_cycles_max(&self) -> Option<u64> {
        let get = |n: &str| self.steps.iter().find(|s| s.name == n && !s.outside).map(|s| s.cycles_max);
        Some(get("control_step")? + get("supervisor_slow")?)
    }

    fn named(&self, reasons: impl Fn(&StepFigures) -> Vec<String>) -> Vec<String> {
        self.steps
            .iter()
            .filter_map(|s| {
                let e = reasons(s);
                (!e.is_empty()).then(|| format!("{}: {}", s.name, e.join(", ")))
            })
            .collect()
    }
}

/// Plain-text table of a report.
pub fn table(r: &Report) -> String {
    let head = |title: &str| {
        format!(
            "{:<20} {:>6} {:>8} {:>13} {:>6}  {:<14} {}\n",
            title, "instr", "mean", "cycles", "stack", "budget", "status"
        )
    };
    let row = |st: &StepFigures| {
        let budget = st.budget.map_or_else(|| "-".to_owned(), |b| format!("{} / {} B", b.instructions, b.stack_bytes));
        let status = match (st.budget, st.excess().is_empty()) {
            (None, _) => "",
            (Some(_), true) => "ok",
            (Some(_), false) if st.over_ceiling().is_empty() => "OVER target (under the CI ceiling)",
            (Some(_), false) => "OVER",
        };
        format!(
            "{:<20} {:>6} {:>8.1} {:>13} {:>5}B  {:<14} {}\n",
            st.name,
            st.instructions,
            st.mean_instructions,
            format!("{}-{}", st.cycles_min, st.cycles_max),
            st.stack_bytes,
            budget,
            status
        )
    };
    let mut s = head("step (20 kHz sweep)");
    for st in r.steps.iter().filter(|s| !s.outside) {
        s += &row(st);
    }
    if let Some(cs) = r.steps.iter().find(|s| s.name == "control_step" && !s.outside) {
        s += &format!(
            "control_step at {:.0} kHz on {:.0} MHz: {:.1}-{:.1} % of the CPU (worst call)\n",
            CONTROL_HZ / 1e3,
            CORE_HZ / 1e6,
            100.0 * cs.cycles_min as f64 * CONTROL_HZ / CORE_HZ,
            100.0 * cs.cycles_max as f64 * CONTROL_HZ / CORE_HZ
        );
    }
    if r.steps.iter().any(|s| s.outside) {
        s += "\n";
        s += &head("outside the envelope");
        for st in r.steps.iter().filter(|s| s.outside) {
            s += &row(st);
        }
    }
    if let Some(i) = &r.interrupts {
        s += &interrupts(r, i);
    }
    s
}

/// The interrupt section of the table: call graphs, f64 helpers, masking.
fn interrupts(r: &Report, i: &Interrupts) -> String {
    let mut s = String::from("\nfirmware interrupts as built (static call graph of the shipping ELF)\n");
    for root in &i.roots {
        s += &format!(
            "{}: {} functions, f64 soft-float helpers: {}, masks interrupts: {}\n",
            root.name,
            root.call_graph.len(),
            if root.f64_soft_float.is_empty() { "none".to_owned() } else { root.f64_soft_float.join(", ") },
            if root.masking.is_empty() { "no".to_owned() } else { root.masking.join(", ") },
        );
        s += &tree(root);
    }
    if let Some(c) = r.isr_cycles_max() {
        s += &format!(
            "control interrupt with the slow pass in its tail: <= {c} cycles of {} a period\n",
            (CORE_HZ / CONTROL_HZ) as u64
        );
    }
    s += &masked("in the interrupts (the slow pass included)", &i.interrupt_masked);
    s += &masked("in thread mode", &i.thread_masked);
    s
}

fn masked(where_: &str, m: &Masked) -> String {
    if m.instructions == 0 && m.cycles_max == 0 {
        return format!("longest interrupt-masked stretch {where_}: 0 cycles (no cpsid)\n");
    }
    format!(
        "longest interrupt-masked stretch {where_}: {} instructions, <= {} cycles ({}{})\n",
        m.instructions,
        m.cycles_max,
        m.function,
        if m.calls.is_empty() { String::new() } else { format!("; calls {}", m.calls.join(", ")) }
    )
}
