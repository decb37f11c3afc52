//! Cortex-M4(F) cycle bounds of each instruction from the ELF's disassembly
//! (`llvm-objdump -d`), with the timings of ARM DDI 0439 §3.3 (FPU: §7.2); see the
//! [`budget`](super) module doc for the classes.

use std::collections::HashMap;

/// Cycle bounds of one instruction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Cycles {
    pub min: u32,
    pub max: u32,
}

/// Cycle bounds `min..=max`.
pub(crate) const fn c(min: u32, max: u32) -> Cycles {
    Cycles { min, max }
}

const CONDS: [&str; 16] =
    ["eq", "ne", "cs", "hs", "cc", "lo", "mi", "pl", "vs", "vc", "hi", "ls", "ge", "lt", "gt", "le"];

/// Registers in a `{r4, r5, lr}` / `{d8-d15}` list, in 32-bit words (a `d` register is 2).
fn reg_words(operands: &str) -> (u32, bool) {
    let (Some(a), Some(b)) = (operands.find('{'), operands.find('}')) else { return (1, false) };
    let list = operands.get(a + 1..b).unwrap_or("");
    let (mut n, mut pc) = (0u32, false);
    for r in list.split(',').map(str::trim).filter(|r| !r.is_empty()) {
        let width = if r.starts_with('d') { 2 } else { 1 };
        if r == "pc" {
            pc = true;
        }
        let count = match r.split_once('-') {
            Some((lo, hi)) => {
                let num = |s: &str| s.trim_start_matches(|ch: char| ch.is_ascii_alphabetic()).parse::<u32>().ok();
                match (num(lo), num(hi)) {
                    (Some(l), Some(h)) if h >= l => h - l + 1,
                    _ => 1,
                }
            }
            None => 1,
        };
        n += width * count;
    }
    (n.max(1), pc)
}

/// Cortex-M4(F) cycle bounds of one instruction from its disassembly (see the module doc).
pub fn cycles_of(mnemonic: &str, operands: &str) -> Cycles {
    let base = mnemonic.split('.').next().unwrap_or(mnemonic);
    // `name`, `name<cond>`, `name s`, `name s<cond>`
    let is = |name: &str| {
        base == name
            || base.strip_prefix(name).is_some_and(|rest| {
                let rest = rest.strip_prefix('s').unwrap_or(rest);
                rest.is_empty() || CONDS.contains(&rest)
            })
    };
    let writes_pc = operands.split(',').next().is_some_and(|d| d.trim() == "pc");
    if is("vdiv") || is("vsqrt") {
        return c(14, 14);
    }
    if ["vmla", "vmls", "vnmla", "vnmls", "vfma", "vfms", "vfnma", "vfnms"].iter().any(|n| is(n)) {
        return c(3, 3);
    }
    if ["vpush", "vpop", "vldmia", "vldmdb", "vstmia", "vstmdb", "vldm", "vstm"].iter().any(|n| is(n)) {
        let (n, _) = reg_words(operands);
        return c(1 + n, 1 + n);
    }
    if is("vldr") || is("vstr") {
        return c(1, 2);
    }
    if is("vmov") && operands.matches(',').count() >= 3 {
        return c(2, 2);
    }
    if ["push", "pop", "ldm", "ldmia", "ldmdb", "stm", "stmia", "stmdb"].iter().any(|n| is(n)) {
        let (n, pc) = reg_words(operands);
        return if pc { c(1 + n + 1, 1 + n + 3) } else { c(1 + n, 1 + n) };
    }
    if is("ldrd") || is("strd") {
        return c(2, 3);
    }
    if ["ldr", "ldrb", "ldrh", "ldrsb", "ldrsh", "str", "strb", "strh", "ldrex", "strex"].iter().any(|n| is(n)) {
        return if writes_pc && base.starts_with("ldr") { c(3, 5) } else { c(1, 2) };
    }
    // Branches take a condition but no `s`: `bls` is `b` + `ls`, not `bl` + `s`.
    let branch = |name: &str| base == name || base.strip_prefix(name).is_some_and(|rest| CONDS.contains(&rest));
    if branch("b") || branch("cbz") || branch("cbnz") {
        return c(1, 4);
    }
    if branch("bl") || branch("blx") || branch("bx") {
        return c(2, 4);
    }
    if is("tbb") || is("tbh") {
        return c(3, 5);
    }
    if is("sdiv") || is("udiv") {
        return c(2, 12);
    }
    if is("mla") || is("mls") {
        return c(2, 2);
    }
    if base.starts_with("it") && base.len() <= 5 && base.chars().skip(1).all(|ch| ch == 't' || ch == 'e') {
        return c(0, 1);
    }
    if writes_pc {
        return c(2, 4);
    }
    c(1, 1)
}

/// Parse `llvm-objdump -d --no-show-raw-insn` lines `    addr:  \tmnemonic\toperands`.
pub fn parse_disassembly(text: &str) -> HashMap<u32, Cycles> {
    let mut map = HashMap::new();
    for line in text.lines() {
        let Some((addr, rest)) = line.split_once(':') else { continue };
        let addr = addr.trim();
        if addr.is_empty() || !addr.bytes().all(|b| b.is_ascii_hexdigit()) || !line.starts_with(' ') {
            continue;
        }
        let Ok(a) = u32::from_str_radix(addr, 16) else { continue };
        let mut it = rest.split('\t').map(str::trim).filter(|s| !s.is_empty());
        let Some(mnemonic) = it.next() else { continue };
        if mnemonic.starts_with('<') || mnemonic.starts_with('.') {
            continue;
        }
        let operands = it.next().unwrap_or("");
        map.insert(a, cycles_of(mnemonic, operands));
    }
    map
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cycle_classes() {
        assert_eq!(cycles_of("vdiv.f32", "s0, s1, s2"), c(14, 14));
        assert_eq!(cycles_of("vsqrt.f32", "s0, s1"), c(14, 14));
        assert_eq!(cycles_of("vmla.f32", "s0, s1, s2"), c(3, 3));
        assert_eq!(cycles_of("vmls.f32", "s0, s1, s2"), c(3, 3));
        assert_eq!(cycles_of("vmovls.f32", "s0, s1"), c(1, 1));
        assert_eq!(cycles_of("vadd.f32", "s0, s1, s2"), c(1, 1));
        assert_eq!(cycles_of("push", "{r4, r5, r7, lr}"), c(5, 5));
        assert_eq!(cycles_of("pop", "{r4, r5, r7, pc}"), c(6, 8));
        assert_eq!(cycles_of("vpush", "{d8, d9, d10}"), c(7, 7));
        assert_eq!(cycles_of("vpop", "{d8-d15}"), c(17, 17));
        assert_eq!(cycles_of("ldr.w", "r0, [r1, #4]"), c(1, 2));
        assert_eq!(cycles_of("ldrd", "r0, r1, [r2]"), c(2, 3));
        assert_eq!(cycles_of("bls", "0x100"), c(1, 4));
        assert_eq!(cycles_of("bl", "0x100"), c(2, 4));
        assert_eq!(cycles_of("bx", "lr"), c(2, 4));
        assert_eq!(cycles_of("itt", "eq"), c(0, 1));
        assert_eq!(cycles_of("adds", "r0, #1"), c(1, 1));
        assert_eq!(cycles_of("mla", "r0, r1, r2, r3"), c(2, 2));
        assert_eq!(cycles_of("udiv", "r0, r1, r2"), c(2, 12));
        assert_eq!(cycles_of("mov", "pc, lr"), c(2, 4));
    }

    #[test]
    fn disassembly_lines() {
        let text = "\n00000100 <foo>:\n     100:      \tpush\t{r4, lr}\n     102:      \tvdiv.f32\ts0, s1, s2\n";
        let m = parse_disassembly(text);
        assert_eq!(m.get(&0x100), Some(&c(3, 3)));
        assert_eq!(m.get(&0x102), Some(&c(14, 14)));
        assert_eq!(m.len(), 2);
    }
}
