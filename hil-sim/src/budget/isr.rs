//! The shipping firmware's interrupts as built: the static call graph of each root
//! (`ADC1_2`, the control interrupt with the slow pass in its tail; `TIM1_UP_TIM16`, the
//! deadline monitor) from the ELF's disassembly (`llvm-objdump -d -C`), the f64
//! soft-float helpers reachable from it (none allowed: the M4F's FPU is single precision,
//! so every f64 operation is a call, `__aeabi_d*` 50–150 cycles each; `--check` fails on
//! one), and where interrupts are masked (`cpsid i`): none in the interrupts (the monitor
//! must pre-empt a stuck step), and the longest straight-line masked stretch, in cycles
//! (upper bound from [`cycles_of`]; a call inside the stretch is named, its callee's
//! cycles added once), in the interrupts' code (the slow pass runs in the control
//! interrupt's tail) and anywhere in thread mode.
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

/// Soft-float f64 helpers of compiler-builtins / the AEABI: every f64 operation on a
/// single-precision FPU (arithmetic, comparison, conversion from or to f64).
/// - AEABI (ARM IHI 0043): `__aeabi_d…` (`dadd`, `dmul`, `dcmpeq`, `d2f`, `d2iz`, …),
///   `__aeabi_cd…` (`cdcmple`, …) and the conversions to f64 `__aeabi_{f,i,ui,l,ul}2d`;
/// - libgcc / compiler-builtins names with the `df` (f64) mode: `__adddf3`, `__eqdf2`,
///   `__extendsfdf2`, `__truncdfsf2`, `__fixdfsi`, `__floatsidf`, `__powidf2`, …
///
/// A demangled path (`compiler_builtins::float::mul::__muldf3`) is judged by its last part.
pub fn is_f64_helper(name: &str) -> bool {
    let last = name.rsplit("::").find(|seg| !is_hash(seg)).unwrap_or(name);
    if let Some(a) = last.strip_prefix("__aeabi_") {
        return a.starts_with('d') && !a.starts_with("div")
            || a.starts_with("cd")
            || ["f2d", "i2d", "ui2d", "l2d", "ul2d"].contains(&a);
    }
    let Some(g) = last.strip_prefix("__") else { return false };
    // `<op>df2`/`<op>df3` (arithmetic, comparisons, powi), `…sfdf2`/`…dfsf2` (f32 ↔ f64),
    // `fix[uns]df{si,di,ti}` and `float[un]{si,di,ti}df` (integers ↔ f64).
    let int_modes = ["si", "di", "ti"];
    g.ends_with("df2")
        || g.ends_with("df3")
        || g.contains("dfsf")
        || (g.starts_with("fix") && int_modes.iter().any(|m| g.ends_with(&format!("df{m}"))))
        || (g.starts_with("float") && int_modes.iter().any(|m| g.ends_with(&format!("{m}df"))))
}

/// The `h0123456789abcdef` hash part of a demangled legacy Rust symbol.
fn is_hash(seg: &str) -> bool {
    seg.len() == 17 && seg.starts_with('h') && seg.bytes().skip(1).all(|b| b.is_ascii_hexdigit())
}

/// One interrupt's call graph.
#[derive(Clone, Debug, Serialize)]
pub struct Root {
    pub name: String,
    /// Reachable functions with their direct callees (sorted).
    pub call_graph: Vec<(String, Vec<String>)>,
    /// Reachable f64 soft-float helpers (must be empty).
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
    /// The longest masked stretch in the code the interrupts reach (the control
    /// interrupt's includes the slow pass); empty (0 cycles) when none masks.
    pub interrupt_masked: Masked,
    /// Thread mode's longest masked stretch.
    pub thread_masked: Masked,
}

impl Interrupts {
    /// What `--check` refuses: an f64 soft-float helper reachable from an interrupt, or
    /// masking in one.
    pub fn violations(&self) -> Vec<String> {
        let mut v = Vec::new();
        for r in &self.roots {
            if !r.f64_soft_float.is_empty() {
                v.push(format!("{}: f64 soft-float reachable: {}", r.name, r.f64_soft_float.join(", ")));
            }
            if !r.masking.is_empty() {
                v.push(format!("{}: masks interrupts in {}", r.name, r.masking.join(", ")));
            }
        }
        v
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

/// The longest straight-line stretch after a `cpsid` in the functions `within` selects.
fn longest_masked(p: &Program, within: impl Fn(&str) -> bool) -> Masked {
    let mut best = Masked::default();
    for (f, insns) in p.iter().filter(|(f, _)| within(f)) {
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
    Ok(Interrupts {
        interrupt_masked: longest_masked(&p, |f| in_interrupts.contains(f) && !is_panic_entry(f)),
        thread_masked: longest_masked(&p, |f| !in_interrupts.contains(f)),
        roots,
    })
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

08000480 <TIM1_UP_TIM16>:
 8000480:      \tbx\tlr

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
        let m = longest_masked(&p, |_| true);
        assert_eq!((m.function.as_str(), m.instructions), ("thread", 2));
        assert!(m.cycles_max >= 2);
        // The interrupt's own code masks nothing.
        let r = root(&p, "ADC1_2");
        let m = longest_masked(&p, |f| r.call_graph.iter().any(|(g, _)| g == f));
        assert_eq!((m.instructions, m.cycles_max), (0, 0));
    }

    #[test]
    fn an_f64_helper_in_an_interrupt_is_a_violation() {
        let p = parse(DIS);
        let i = Interrupts {
            roots: vec![root(&p, "ADC1_2")],
            interrupt_masked: Masked::default(),
            thread_masked: Masked::default(),
        };
        assert_eq!(i.violations(), vec!["ADC1_2: f64 soft-float reachable: __aeabi_dmul".to_owned()]);
        let clean = Interrupts { roots: vec![root(&p, "TIM1_UP_TIM16")], ..i };
        assert!(clean.violations().is_empty(), "{:?}", clean.violations());
    }

    #[test]
    fn every_f64_helper_name_is_recognised() {
        let f64_helpers = [
            "__aeabi_dadd",
            "__aeabi_ddiv",
            "__aeabi_dmul",
            "__aeabi_drsub",
            "__aeabi_dsub",
            "__aeabi_dneg",
            "__aeabi_dcmpeq",
            "__aeabi_dcmpun",
            "__aeabi_cdcmple",
            "__aeabi_cdrcmple",
            "__aeabi_d2f",
            "__aeabi_d2iz",
            "__aeabi_d2uiz",
            "__aeabi_d2lz",
            "__aeabi_d2ulz",
            "__aeabi_f2d",
            "__aeabi_i2d",
            "__aeabi_ui2d",
            "__aeabi_l2d",
            "__aeabi_ul2d",
            "compiler_builtins::float::add::__adddf3",
            "compiler_builtins::float::div::__divdf3",
            "__muldf3",
            "__subdf3",
            "__negdf2",
            "__eqdf2",
            "__unorddf2",
            "__powidf2",
            "__extendsfdf2",
            "__truncdfsf2",
            "__fixdfsi",
            "__fixunsdfdi",
            "__floatsidf",
            "__floatundidf",
        ];
        for h in f64_helpers {
            assert!(is_f64_helper(h), "{h}");
        }
        let not_f64 = [
            "__aeabi_fadd",
            "__aeabi_fmul",
            "__aeabi_f2iz",
            "__aeabi_i2f",
            "__aeabi_memcpy4",
            "__aeabi_memclr8",
            "__aeabi_uidiv",
            "__aeabi_idivmod",
            "__aeabi_ldivmod",
            "__addsf3",
            "__floatsisf",
            "__udivdi3",
            "compiler_builtins::mem::memcpy",
            "libm::math::tanf::tanf::h3508fa608e849d83",
            "model_core::math::tan::h0123456789abcdef",
            "_defmt_acquire",
        ];
        for h in not_f64 {
            assert!(!is_f64_helper(h), "{h}");
        }
    }
}
