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
/// One model's control interrupt at the rate the firmware runs it (issue 17): its
/// `control_step_<id>` and `supervisor_slow_<id>` worst cycles against
/// [`firmware::runner::fits`] at [`firmware::runner::control_hz_of`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ModelRate {
    pub model: String,
    /// The firmware's rate for the model, Hz (`None`: the firmware does not run it).
    pub control_hz: Option<u32>,
    pub step_cycles: u64,
    /// The slow pass's worst cycles (0 when not measured).
    pub slow_cycles: u64,
    /// `step · control_hz + slow · SLOW_HZ` in percent of the core.
    pub cpu_percent: f64,
    /// Step + slow pass as a percentage of one control period.
    pub period_percent: f64,
    /// Within the deadline and the CPU share at its rate.
    pub fits: bool,
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
        v.extend(self.rate_violations());
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

    /// Every model's control interrupt at its firmware rate, from the `control_step_<id>`
    /// rows (in the order measured).
    pub fn model_rates(&self) -> Vec<ModelRate> {
        let cycles = |n: &str| self.steps.iter().find(|s| s.name == n && !s.outside).map(|s| s.cycles_max);
        self.steps
            .iter()
            .filter(|s| !s.outside)
            .filter_map(|s| s.name.strip_prefix("control_step_").map(|id| (id, s.cycles_max)))
            .map(|(id, step)| {
                let slow = cycles(&format!("supervisor_slow_{id}")).unwrap_or(0);
                let control_hz = firmware::runner::control_hz_of(id);
                let hz = f64::from(control_hz.unwrap_or(0));
                let slow_hz = f64::from(firmware::runner::SLOW_HZ);
                ModelRate {
                    model: id.to_owned(),
                    control_hz,
                    step_cycles: step,
                    slow_cycles: slow,
                    cpu_percent: 100.0 * (step as f64 * hz + slow as f64 * slow_hz) / CORE_HZ,
                    period_percent: 100.0 * (step + slow) as f64 * hz / CORE_HZ,
                    fits: control_hz.is_some_and(|hz| firmware::runner::fits(step, slow, hz)),
                }
            })
            .collect()
    }

    /// The models the firmware runs whose control interrupt does not fit at their rate, or
    /// that the bench did not measure.
    pub fn rate_violations(&self) -> Vec<String> {
        let rates = self.model_rates();
        let mut v: Vec<String> = rates
            .iter()
            .filter(|r| r.control_hz.is_some() && !r.fits)
            .map(|r| {
                format!(
                    "control_step_{}: {} + {} cycles (slow pass) do not fit at {} Hz ({:.0} % of the period, {:.1} % \
                     of the CPU; share {} %)",
                    r.model,
                    r.step_cycles,
                    r.slow_cycles,
                    r.control_hz.unwrap_or(0),
                    r.period_percent,
                    r.cpu_percent,
                    firmware::runner::CPU_SHARE_PERCENT
                )
            })
            .collect();
        if !rates.is_empty() {
            for id in firmware::runner::MODELS {
                if !rates.iter().any(|r| r.model == id) {
                    v.push(format!("control_step_{id}: not measured (the firmware runs {id})"));
                }
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
    let rates = r.model_rates();
    if !rates.is_empty() {
        s += &format!(
            "\ncontrol rate per model (firmware::runner; share: step at the rate + slow pass at {} Hz <= {} % of the CPU, \
             step + slow pass within a period)\n{:<20} {:>8} {:>8} {:>8} {:>7} {:>7}  {}\n",
            firmware::runner::SLOW_HZ,
            firmware::runner::CPU_SHARE_PERCENT,
            "model",
            "rate Hz",
            "step",
            "slow",
            "CPU %",
            "period%",
            "status"
        );
        for m in &rates {
            s += &format!(
                "{:<20} {:>8} {:>8} {:>8} {:>7.1} {:>7.1}  {}\n",
                m.model,
                m.control_hz.map_or_else(|| "-".to_owned(), |h| h.to_string()),
                m.step_cycles,
                m.slow_cycles,
                m.cpu_percent,
                m.period_percent,
                match (m.control_hz, m.fits) {
                    (None, _) => "not in the firmware",
                    (Some(_), true) => "ok",
                    (Some(_), false) => "OVER",
                }
            );
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    fn row(name: &str, cycles_max: u64) -> StepFigures {
        StepFigures { name: name.to_owned(), cycles_max, ..StepFigures::default() }
    }

    fn report(step: impl Fn(&str) -> Option<(u64, u64)>) -> Report {
        let mut steps = Vec::new();
        for id in firmware::runner::MODELS {
            if let Some((c, s)) = step(id) {
                steps.push(row(&format!("control_step_{id}"), c));
                steps.push(row(&format!("supervisor_slow_{id}"), s));
            }
        }
        Report { elf: PathBuf::new(), machine: "test", steps, traced_instructions: 0, interrupts: None }
    }

    #[test]
    fn every_firmware_model_needs_a_row_that_fits_at_its_rate() {
        // The figures of 2026-11-24 fit at the runner's rates.
        let measured = |id: &str| match id {
            "gpi" => Some((1977, 7224)),
            "preisach" => Some((1957, 9028)),
            "hammerstein_wiener" => Some((6738, 17339)),
            "narx" => Some((56508, 9704)),
            _ => Some((1720, 6624)),
        };
        let r = report(measured);
        assert_eq!(r.model_rates().len(), firmware::runner::MODELS.len());
        assert!(r.model_rates().iter().all(|m| m.fits && m.control_hz.is_some()));
        assert!(r.rate_violations().is_empty(), "{:?}", r.rate_violations());
        // A step that grew past its share, and a model the bench no longer measures.
        let r = report(|id| match id {
            "preisach" => None,
            "narx" => Some((90_000, 9704)),
            _ => measured(id),
        });
        let v = r.rate_violations();
        assert_eq!(v.len(), 2, "{v:?}");
        assert!(v.iter().any(|e| e.starts_with("control_step_narx:") && e.contains("1000 Hz")), "{v:?}");
        assert!(v.iter().any(|e| e.contains("control_step_preisach: not measured")), "{v:?}");
        assert_eq!(r.over_ceiling(), v);
    }
}
