//! The bench's semihosting output (`step|outside <name> <address> <calls>` lines) and the
//! streaming parser of QEMU's `-d exec,cpu,nochain` log: for every call of a measured
//! function, instructions from entry to the return to its caller (`pc == lr` with the entry
//! SP), cycle bounds, and the stack below the entry SP (bytes).

use std::collections::HashMap;

use super::cycles::{c, Cycles};
use super::error::BudgetError;
use super::figures::StepFigures;
use super::table::BUDGETS;

/// One `step|outside <name> <address> <calls>` line of the bench.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Marker {
    pub name: String,
    /// A sweep beyond the 20 kHz operating envelope (reported apart, no budget).
    pub outside: bool,
    /// Entry address (Thumb bit cleared).
    pub address: u32,
    /// Calls the bench makes.
    pub calls: u64,
}

/// Read the bench's semihosting output. Errors on an `error …` line or a missing `done`.
pub fn parse_markers(stdout: &str) -> Result<Vec<Marker>, BudgetError> {
    let mut out = Vec::new();
    let mut done = false;
    for line in stdout.lines().map(str::trim) {
        let mut it = line.split_whitespace();
        match it.next() {
            Some(kind @ ("step" | "outside")) => {
                let (Some(name), Some(addr), Some(calls)) = (it.next(), it.next(), it.next()) else {
                    return Err(BudgetError::MalformedLine { line: line.to_owned() });
                };
                let address = u32::from_str_radix(addr.trim_start_matches("0x"), 16)
                    .map_err(|source| BudgetError::BadAddress { line: line.to_owned(), source })?;
                let calls = calls.parse().map_err(|source| BudgetError::BadCalls { line: line.to_owned(), source })?;
                out.push(Marker { name: name.to_owned(), outside: kind == "outside", address: address & !1, calls });
            }
            Some("error") => return Err(BudgetError::BenchReported { line: line.to_owned() }),
            Some("done") => done = true,
            _ => {}
        }
    }
    if !done {
        return Err(BudgetError::Unfinished);
    }
    if out.is_empty() {
        return Err(BudgetError::NoSteps);
    }
    Ok(out)
}

#[derive(Clone, Copy, Debug)]
struct Open {
    marker: usize,
    ret: u32,
    sp0: u32,
    min_sp: u32,
    instructions: u64,
    cyc: Cycles,
}

#[derive(Clone, Copy, Debug, Default)]
struct Acc {
    calls: u64,
    total: u64,
    max: u64,
    cyc_min: u64,
    cyc_max: u64,
    stack: u32,
}

/// Streaming parser of QEMU's `-d exec,cpu,nochain` log.
pub struct Tracer<'a> {
    markers: &'a [Marker],
    /// Entry address → the markers measuring it, in the bench's order (a function swept
    /// twice is attributed to its first marker until that one has all its calls).
    entries: HashMap<u32, Vec<usize>>,
    cycles: &'a HashMap<u32, Cycles>,
    open: Option<Open>,
    acc: Vec<Acc>,
    pc: Option<u32>,
    /// Instructions seen in the whole log.
    pub executed: u64,
    /// Executed addresses missing from the disassembly (counted as 1 cycle).
    pub unknown: u64,
}

fn hex_after(line: &[u8], key: &[u8]) -> Option<u32> {
    let at = line.windows(key.len()).position(|w| w == key)? + key.len();
    let digits = line.get(at..at + 8)?;
    u32::from_str_radix(std::str::from_utf8(digits).ok()?, 16).ok()
}

impl<'a> Tracer<'a> {
    pub fn new(markers: &'a [Marker], cycles: &'a HashMap<u32, Cycles>) -> Self {
        let mut entries: HashMap<u32, Vec<usize>> = HashMap::new();
        for (i, m) in markers.iter().enumerate() {
            entries.entry(m.address).or_default().push(i);
        }
        Self {
            markers,
            entries,
            cycles,
            open: None,
            acc: vec![Acc::default(); markers.len()],
            pc: None,
            executed: 0,
            unknown: 0,
        }
    }

    /// Feed one log line.
    pub fn line(&mut self, line: &[u8]) {
        if line.starts_with(b"Trace ") {
            // `Trace 0: 0x7f… [flags/PC/flags/flags] `
            if let Some(open) = line.iter().position(|&b| b == b'[') {
                let fields = line.get(open + 1..).unwrap_or(&[]);
                let pc = fields
                    .split(|&b| b == b'/')
                    .nth(1)
                    .and_then(|f| std::str::from_utf8(f).ok())
                    .and_then(|f| u32::from_str_radix(f.trim_end_matches([']', ' ']), 16).ok());
                self.pc = pc;
            }
        } else if line.starts_with(b"R12=") {
            if let (Some(pc), Some(sp), Some(lr)) = (self.pc.take(), hex_after(line, b"R13="), hex_after(line, b"R14="))
            {
                self.instruction(pc & !1, sp, lr);
            }
        }
    }

    fn instruction(&mut self, pc: u32, sp: u32, lr: u32) {
        self.executed += 1;
        let cyc = match self.cycles.get(&pc) {
            Some(c) => *c,
            None => {
                self.unknown += 1;
                c(1, 1)
            }
        };
        match self.open.as_mut() {
            Some(o) if pc == o.ret && sp == o.sp0 => {
                let o = *o;
                self.open = None;
                let a = &mut self.acc[o.marker];
                a.calls += 1;
                a.total += o.instructions;
                a.max = a.max.max(o.instructions);
                a.cyc_min = a.cyc_min.max(u64::from(o.cyc.min));
                a.cyc_max = a.cyc_max.max(u64::from(o.cyc.max));
                a.stack = a.stack.max(o.sp0 - o.min_sp);
            }
            Some(o) => {
                o.instructions += 1;
                o.cyc.min += cyc.min;
                o.cyc.max += cyc.max;
                o.min_sp = o.min_sp.min(sp);
            }
            None => {
                let marker = self.entries.get(&pc).and_then(|list| {
                    list.iter().copied().find(|&i| self.acc[i].calls < self.markers[i].calls).or(list.last().copied())
                });
                if let Some(marker) = marker {
                    self.open = Some(Open { marker, ret: lr & !1, sp0: sp, min_sp: sp, instructions: 1, cyc });
                }
            }
        }
    }

    /// The figures, in the bench's order. Errors when a step was called fewer times than
    /// the bench announced (a truncated trace).
    pub fn finish(self) -> Result<Vec<StepFigures>, BudgetError> {
        if self.open.is_some() {
            return Err(BudgetError::TraceEndedInCall);
        }
        let mut out = Vec::new();
        for (m, a) in self.markers.iter().zip(&self.acc) {
            if a.calls != m.calls {
                return Err(BudgetError::CallsMismatch { name: m.name.clone(), traced: a.calls, made: m.calls });
            }
            out.push(StepFigures {
                name: m.name.clone(),
                instructions: a.max,
                mean_instructions: a.total as f64 / a.calls.max(1) as f64,
                cycles_min: a.cyc_min,
                cycles_max: a.cyc_max,
                stack_bytes: a.stack,
                calls: a.calls,
                outside: m.outside,
                budget: if m.outside { None } else { BUDGETS.iter().find(|b| b.name == m.name).copied() },
            });
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markers_and_errors() {
        let m = parse_markers("step algebraic 0xdf0d 212\nstep control_step 0x14a4 400\ndone\n").unwrap();
        assert_eq!(m[0], Marker { name: "algebraic".into(), outside: false, address: 0xdf0c, calls: 212 });
        assert_eq!(m[1].address, 0x14a4);
        assert!(parse_markers("step a 0x10 1\n").unwrap_err().to_string().contains("did not finish"));
        assert!(parse_markers("error lugre: bad\n").unwrap_err().to_string().contains("lugre: bad"));
    }

    /// A synthetic log: the bench calls 0x100 twice from 0x20; the step pushes 8 bytes,
    /// calls a helper at 0x200 that pushes 8 more, and returns.
    #[test]
    fn tracer_counts_calls_instructions_and_stack() {
        let markers = vec![
            Marker { name: "algebraic".into(), outside: false, address: 0x100, calls: 1 },
            Marker { name: "algebraic".into(), outside: true, address: 0x100, calls: 1 },
        ];
        let cycles: HashMap<u32, Cycles> =
            [(0x100, c(3, 3)), (0x102, c(1, 1)), (0x200, c(3, 3)), (0x202, c(3, 5)), (0x104, c(3, 5))]
                .into_iter()
                .collect();
        let mut t = Tracer::new(&markers, &cycles);
        let mut feed = |pc: u32, sp: u32, lr: u32| {
            t.line(format!("Trace 0: 0x7f00 [00000000/{pc:08x}/00000000/ff000201] \n").as_bytes());
            t.line(b"R00=00000000 R01=00000000 R02=00000000 R03=00000000\n");
            t.line(format!("R12=00000000 R13={sp:08x} R14={lr:08x} R15={pc:08x}\n").as_bytes());
        };
        for _ in 0..2 {
            feed(0x1e, 0x2000_1000, 0);
            feed(0x100, 0x2000_1000, 0x21); // entry: push
            feed(0x102, 0x2000_0ff8, 0x21); // bl helper
            feed(0x200, 0x2000_0ff8, 0x107); // helper: push
            feed(0x202, 0x2000_0ff0, 0x107); // helper: pop pc
            feed(0x104, 0x2000_0ff8, 0x107); // pop pc
            feed(0x20, 0x2000_1000, 0x107); // back in the bench
        }
        let f = t.finish().unwrap();
        assert_eq!((f[0].calls, f[1].calls), (1, 1));
        assert!(f[1].outside && f[1].budget.is_none());
        assert_eq!(f[0].instructions, 5);
        assert_eq!(f[0].stack_bytes, 16);
        assert_eq!((f[0].cycles_min, f[0].cycles_max), (13, 17));
        assert!(f[0].excess().is_empty());
        let over = StepFigures { instructions: 31, stack_bytes: 20, ..f[0].clone() };
        assert_eq!(over.excess().len(), 2);
    }
}
