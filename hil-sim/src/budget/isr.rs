//! The shipping firmware's interrupts as built: the static call graph of each root
//! (`ADC1_2`, the control interrupt with the slow pass in its tail; `TIM1_UP_TIM16`, the
//! deadline monitor) from the ELF's disassembly (`llvm-objdump -d -C`), the f64
//! soft-float helpers reachable from it (reported: `__aeabi_d*` costs 50–150 cycles a
//! call on the single-precision FPU), and where interrupts are masked (`cpsid i`): none
//! in the interrupts (the monitor must pre-empt a stuck step), and the longest
//! straight-line masked stretch anywhere in thread mode, in cycles (upper bound from
//! [`cycles_of`]; a call inside the stretch is named, its callee's cycles added once).
//! Panic paths (`core::panicking::*`, …) are leaves: the panic handler masks interrupts on
//! purpose once the bridge is off, and never returns.

use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::path::Path;
use std::process::Command;

use serde::Serialize;

use super::cycles::cycles_of;
use super::error::BudgetError;

/// One disassembled instruction.
#[derive(Clone, Debug)]
struct Insn {
    mnemonic: String,
    operands: String,
    /// The `<symbol>` a branch names (without `+0x…`).
    target: Option<String>,
}

/// Functions by name, instructions in address order.
type Program = BTreeMap<String, Vec<Insn>>;

/// Soft-float f64 helpers of compiler-builtins / the AEABI.
pub fn is_f64_helper(name: &str) -> bool {
    name.starts_with("__aeabi_d")
        || name.starts_with("__aeabi_f2d")
        || ["adddf3", "subdf3", "muldf3", "divdf3", "extendsfdf2", "truncdfsf2", "floatsidf", "fixdfsi"]
            .iter()
            .any(|h| name.contains(h))
}

/// One interrupt's call graph.
#[derive(Clone, Debug, Serialize)]
pub struct Root {
    pub name: String,
    /// Reachable functions with their direct callees (sorted).
    pub call_graph: Vec<(String, Vec<String>)>,
    /// Reachable f64 soft-float helpers (reported as a warning).
    pub f64_soft_float: Vec<String>,
    /// Reachable functions that execute `cpsid i` (must be empty).
    pub masking: Vec<String>,
    /// Indirect calls (`blx rN`) the static graph cannot follow, by function.
    pub indirect_calls: Vec<String>,
}

/// The longest interrupt-masked straight-line stretch.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Masked {
    pub function: String,
    pub instructions: u64,
    pub cycles_max: u64,
    pub calls: Vec<String>,
}

/// The interrupt figures of the shipping ELF.
#[derive(Clone, Debug, Serialize)]
pub struct Interrupts {
    pub roots: Vec<Root>,
    /// Thread mode's longest masked stretch.
    pub thread_masked: Masked,
}

impl Interrupts {
    /// What `--check` refuses: masking in an interrupt.
    pub fn violations(&self) -> Vec<String> {
        let mut v = Vec::new();
        for r in &self.roots {
            if !r.masking.is_empty() {
                v.push(format!("{}: masks interrupts in {}", r.name, r.masking.join(", ")));
            }
        }
        v
    }

    /// What is reported as a warning: f64 soft-float helpers reachable from an interrupt
    /// (cycles, not correctness: they are measured in the step budgets).
    pub fn warnings(&self) -> Vec<String> {
        self.roots
            .iter()
            .filter(|r| !r.f64_soft_float.is_empty())
            .map(|r| format!("{}: f64 soft-float reachable: {}", r.name, r.f64_soft_float.join(", ")))
            .collect()
    }
}

fn parse(text: &str) -> Program {
    let mut p = Program::new();
    let mut cur: Option<String> = None;
    for line in text.lines() {
        if let Some(name) = line.strip_suffix(">:").and_then(|l| l.split_once(" <")).map(|(_, n)| n) {
            cur = Some(name.to_owned());
            p.entry(name.to_owned()).or_default();
            continue;
        }
        let (Some(f), Some((addr, rest))) = (cur.as_ref(), line.split_once(':')) else { continue };
        if addr.trim().is_empty() || !addr.trim().bytes().all(|b| b.is_ascii_hexdigit()) {
            continue;
        }
        let rest = rest.trim_start_matches([' ', '\t']);
        // `bl\t0x…`, but `cpsid i` with a space.
        let (mnemonic, operands) = rest.split_once(['\t', ' ']).unwrap_or((rest, ""));
        // `0x… <name>` or `<name+0x…>`; demangled names may hold `<…>` themselves.
        let o = operands.split(" @ ").next().unwrap_or("");
        let target = o.find('<').and_then(|a| o.rfind('>').and_then(|b| o.get(a + 1..b))).map(|t| {
            let t = t.rsplit_once('+').map_or(t, |(n, off)| if off.starts_with("0x") { n } else { t });
            t.to_owned()
        });
        if let Some(v) = p.get_mut(f) {
            v.push(Insn { mnemonic: mnemonic.trim().to_owned(), operands: operands.trim().to_owned(), target });
        }
    }
    p
}

fn is_branch(m: &str) -> bool {
    m.starts_with('b') && !m.starts_with("bic") && !m.starts_with("bfi") && !m.starts_with("bfc") && m != "bkpt"
        || m.starts_with("cbz")
        || m.starts_with("cbnz")
}

fn callees(p: &Program, f: &str) -> (BTreeSet<String>, bool) {
    let mut out = BTreeSet::new();
    let mut indirect = false;
    for i in p.get(f).map_or(&[][..], Vec::as_slice) {
        if i.mnemonic == "blx" && !i.operands.contains('<') {
            indirect = true;
        }
        if let Some(t) = &i.target {
            if is_branch(&i.mnemonic) && t != f && p.contains_key(t) {
                out.insert(t.clone());
            }
        }
    }
    (out, indirect)
}

/// Entries of the panic path: listed as leaves, not followed (the panic handler masks
/// interrupts on purpose, after the bridge is off; it never returns to the interrupt).
const PANIC_ENTRIES: [&str; 5] =
    ["core::panicking::", "core::cell::panic_", "core::option::", "core::result::unwrap_failed", "__rustc::"];

fn is_panic_entry(name: &str) -> bool {
    PANIC_ENTRIES.iter().any(|p| name.starts_with(p))
}

fn root(p: &Program, name: &str) -> Root {
    let mut graph = BTreeMap::new();
    let mut queue = VecDeque::from([name.to_owned()]);
    let mut indirect_calls = Vec::new();
    while let Some(f) = queue.pop_front() {
        if graph.contains_key(&f) {
            continue;
        }
        if is_panic_entry(&f) {
            graph.insert(f, Vec::new());
            continue;
        }
        let (calls, indirect) = callees(p, &f);
        if indirect {
            indirect_calls.push(f.clone());
        }
        queue.extend(calls.iter().cloned());
        graph.insert(f, calls.into_iter().collect::<Vec<_>>());
    }
    let f64_soft_float = graph.keys().filter(|f| is_f64_helper(f)).cloned().collect();
    let masking =
        graph.keys().filter(|f| p.get(*f).is_some_and(|v| v.iter().any(|i| i.mnemonic == "cpsid"))).cloned().collect();
    Root { name: name.to_owned(), call_graph: graph.into_iter().collect(), f64_soft_float, masking, indirect_calls }
}

/// Straight-line cycles of a whole function (its instructions once; no loops followed).
fn straight_cycles(p: &Program, f: &str) -> u64 {
    p.get(f).map_or(0, |v| v.iter().map(|i| u64::from(cycles_of(&i.mnemonic, &i.operands).max)).sum())
}

fn thread_masked(p: &Program, interrupt_code: &BTreeSet<String>) -> Masked {
    let mut best = Masked::default();
    for (f, insns) in p.iter().filter(|(f, _)| !interrupt_code.contains(*f)) {
        for (k, _) in insns.iter().enumerate().filter(|(_, i)| i.mnemonic == "cpsid") {
            let mut m = Masked { function: f.clone(), ..Masked::default() };
            for i in insns.iter().skip(k + 1) {
                if i.mnemonic == "cpsie" || (i.mnemonic == "msr" && i.operands.starts_with("primask")) {
                    break;
                }
                m.instructions += 1;
                m.cycles_max += u64::from(cycles_of(&i.mnemonic, &i.operands).max);
                if i.mnemonic == "bl" {
                    if let Some(t) = &i.target {
                        m.cycles_max += straight_cycles(p, t);
                        m.calls.push(t.clone());
                    }
                }
                if i.mnemonic.starts_with("pop") && i.operands.contains("pc") || i.mnemonic == "udf" {
                    break;
                }
            }
            if m.cycles_max > best.cycles_max {
                best = m;
            }
        }
    }
    best
}

/// Analyse the shipping firmware ELF.
pub fn analyse(objdump: &Path, elf: &Path) -> Result<Interrupts, BudgetError> {
    if !elf.is_file() {
        return Err(BudgetError::NoElf(elf.to_path_buf()));
    }
    let out = Command::new(objdump)
        .args(["-d", "-C", "--no-show-raw-insn"])
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
    let p = parse(&String::from_utf8_lossy(&out.stdout));
    let roots: Vec<Root> = ["ADC1_2", "TIM1_UP_TIM16"]
        .iter()
        .map(|r| if p.contains_key(*r) { Ok(root(&p, r)) } else { Err(BudgetError::NoSymbol((*r).to_owned())) })
        .collect::<Result<_, _>>()?;
    let in_interrupts: BTreeSet<String> =
        roots.iter().flat_map(|r| r.call_graph.iter().map(|(f, _)| f.clone())).collect();
    Ok(Interrupts { roots, thread_masked: thread_masked(&p, &in_interrupts) })
}

/// The call graph as an indented tree (each function once, at its first appearance).
pub fn tree(r: &Root) -> String {
    let graph: BTreeMap<&str, &Vec<String>> = r.call_graph.iter().map(|(f, c)| (f.as_str(), c)).collect();
    let mut seen = BTreeSet::new();
    let mut out = String::new();
    let mut stack = vec![(r.name.as_str(), 0usize)];
    while let Some((f, depth)) = stack.pop() {
        let first = seen.insert(f);
        out += &format!("{}{}{}\n", "  ".repeat(depth), f, if first { "" } else { " (above)" });
        if first {
            for c in graph.get(f).map_or(&[][..], |v| v.as_slice()).iter().rev() {
                stack.push((c.as_str(), depth + 1));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const DIS: &str = "\
08000230 <ADC1_2>:
 8000230:      \tpush\t{r7, lr}
 8000238:      \tb.w\t0x80059ac <body> @ imm = #0x5770

080059ac <body>:
 80059ac:      \tbl\t0x8000300 <tanf>
 80059b0:      \tpop\t{r7, pc}

08000300 <tanf>:
 8000300:      \tbl\t0x8000400 <__aeabi_dmul>
 8000304:      \tbx\tlr

08000400 <__aeabi_dmul>:
 8000400:      \tbx\tlr

08000500 <thread>:
 8000500:      \tcpsid i
 8000502:      \tldr\tr0, [r1]
 8000504:      \tstr\tr0, [r2]
 8000506:      \tcpsie i
 8000508:      \tbx\tlr
";

    #[test]
    fn f64_helpers_are_found_through_the_graph() {
        let p = parse(DIS);
        let r = root(&p, "ADC1_2");
        assert_eq!(r.f64_soft_float, vec!["__aeabi_dmul".to_owned()]);
        assert!(r.masking.is_empty());
        assert!(tree(&r).contains("    __aeabi_dmul"), "{}", tree(&r));
    }

    #[test]
    fn masked_stretch_counts_the_instructions_between() {
        let p = parse(DIS);
        let m = thread_masked(&p, &BTreeSet::new());
        assert_eq!((m.function.as_str(), m.instructions), ("thread", 2));
        assert!(m.cycles_max >= 2);
    }
}
