//! The shape of the code base (issue 15): no source file in `model-core/src` or
//! `hil-sim/src` over 600 lines (test files excepted), no function over 120 lines, and no
//! import cycle between modules (parent and child modules may use each other; siblings
//! and rooms may not form a cycle).
//!
//! The sources are read as text: comments and string literals are blanked out, then
//! functions are measured by brace depth from their `fn` line to their closing brace, and
//! each file's `crate::a::b` (and `super::`) paths give the module graph.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

const MAX_FILE_LINES: usize = 600;
const MAX_FN_LINES: usize = 120;

fn root() -> PathBuf {
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    here.parent().map_or_else(|| here.join(".."), Path::to_path_buf)
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir).expect("read_dir").flatten().map(|e| e.path()).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// A file of unit tests (`tests.rs`, `*_tests.rs`) or under a `tests` folder of `src`.
fn is_test_file(p: &Path) -> bool {
    let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
    let in_src = p.strip_prefix(root()).map_or(p, |r| r);
    name == "tests.rs" || name.ends_with("_tests.rs") || in_src.components().any(|c| c.as_os_str() == "tests")
}

/// The source with comments, string and char literals replaced by spaces (line breaks kept).
fn blank(src: &str) -> String {
    let b = src.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let rest = &b[i..];
        if rest.starts_with(b"//") {
            while i < b.len() && b[i] != b'\n' {
                out.push(b' ');
                i += 1;
            }
        } else if rest.starts_with(b"/*") {
            let mut depth = 0;
            while i < b.len() {
                if b[i..].starts_with(b"/*") {
                    depth += 1;
                    out.extend_from_slice(b"  ");
                    i += 2;
                } else if b[i..].starts_with(b"*/") {
                    depth -= 1;
                    out.extend_from_slice(b"  ");
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    out.push(if b[i] == b'\n' { b'\n' } else { b' ' });
                    i += 1;
                }
            }
        } else if rest.starts_with(b"r#\"") || rest.starts_with(b"r\"") {
            let hashes = rest.iter().skip(1).take_while(|&&c| c == b'#').count();
            let close: Vec<u8> = std::iter::once(b'"').chain(std::iter::repeat_n(b'#', hashes)).collect();
            let start = i + 2 + hashes;
            out.extend(std::iter::repeat_n(b' ', start - i));
            i = start;
            while i < b.len() && !b[i..].starts_with(&close) {
                out.push(if b[i] == b'\n' { b'\n' } else { b' ' });
                i += 1;
            }
            let n = close.len().min(b.len() - i);
            out.extend(std::iter::repeat_n(b' ', n));
            i += n;
        } else if b[i] == b'"' {
            out.push(b' ');
            i += 1;
            while i < b.len() && b[i] != b'"' {
                let step = if b[i] == b'\\' { 2 } else { 1 };
                for k in 0..step {
                    if let Some(&c) = b.get(i + k) {
                        out.push(if c == b'\n' { b'\n' } else { b' ' });
                    }
                }
                i += step;
            }
            out.push(b' ');
            i += 1;
        } else if b[i] == b'\'' && is_char_literal(rest) {
            let len = if rest.get(1) == Some(&b'\\') {
                rest.iter().skip(2).position(|&c| c == b'\'').map_or(3, |p| p + 3)
            } else {
                3
            };
            out.extend(std::iter::repeat_n(b' ', len.min(b.len() - i)));
            i += len;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// `'x'` or `'\n'` rather than a lifetime `'a`.
fn is_char_literal(rest: &[u8]) -> bool {
    match rest.get(1) {
        Some(b'\\') => true,
        Some(_) => {
            // One UTF-8 character, then a closing quote.
            let s = String::from_utf8_lossy(&rest[1..rest.len().min(6)]).into_owned();
            let mut chars = s.chars();
            chars.next().is_some() && chars.next() == Some('\'')
        }
        None => false,
    }
}

/// Functions longer than [`MAX_FN_LINES`]: `(name, first line, lines)`.
fn long_functions(code: &str) -> Vec<(String, usize, usize)> {
    let mut out = Vec::new();
    let mut depth = 0usize;
    let mut open: Vec<(String, usize, usize)> = Vec::new();
    let mut pending: Option<(String, usize)> = None;
    for (n, line) in code.lines().enumerate() {
        if let Some(pos) = find_fn(line) {
            let name: String =
                line[pos + 3..].trim_start().chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
            pending = Some((name, n + 1));
        }
        for ch in line.chars() {
            match ch {
                '{' => {
                    depth += 1;
                    if let Some((name, start)) = pending.take() {
                        open.push((name, start, depth));
                    }
                }
                '}' => {
                    if open.last().is_some_and(|f| f.2 == depth) {
                        if let Some((name, start, _)) = open.pop() {
                            let len = n + 1 - start + 1;
                            if len > MAX_FN_LINES {
                                out.push((name, start, len));
                            }
                        }
                    }
                    depth = depth.saturating_sub(1);
                }
                ';' => pending = None,
                _ => {}
            }
        }
    }
    out
}

/// Position of a `fn` keyword in `line`.
fn find_fn(line: &str) -> Option<usize> {
    let b = line.as_bytes();
    (0..b.len().saturating_sub(2))
        .find(|&i| &b[i..i + 3] == b"fn " && (i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_')))
}

/// The module path of a source file (`crate::ident::fit` for `hil-sim/src/ident/fit/mod.rs`).
fn module_of(src_dir: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src_dir).expect("under src");
    let mut parts: Vec<String> = rel.iter().map(|c| c.to_string_lossy().into_owned()).collect();
    let last = parts.pop().unwrap_or_default();
    let stem = last.trim_end_matches(".rs");
    if !matches!(stem, "mod" | "lib" | "main") {
        parts.push(stem.to_owned());
    }
    parts
}

/// Modules a file refers to by `crate::` and `super::` paths.
fn references(code: &str, module: &[String], is_mod_file: bool) -> BTreeSet<Vec<String>> {
    let mut out = BTreeSet::new();
    let words = |s: &str| -> Vec<String> {
        s.split("::")
            .map(|w| w.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect::<String>())
            .take_while(|w| !w.is_empty() && w.chars().next().is_some_and(|c| c.is_ascii_lowercase()))
            .collect()
    };
    for (i, _) in code.match_indices("crate::") {
        out.insert(words(&code[i + 7..]));
    }
    // `super::` from a file `a/b.rs` (module a::b) is `a`; from `a/b/mod.rs` it is also `a`.
    let _ = is_mod_file;
    let parent: Vec<String> = module.iter().take(module.len().saturating_sub(1)).cloned().collect();
    for (i, _) in code.match_indices("super::") {
        if code[..i].ends_with("::") {
            continue;
        }
        let mut p = parent.clone();
        p.extend(words(&code[i + 7..]));
        out.insert(p);
    }
    out
}

/// One line per violation in `crate_dir/src`.
fn violations(crate_dir: &Path) -> Vec<String> {
    let src_dir = crate_dir.join("src");
    let mut files = Vec::new();
    rust_files(&src_dir, &mut files);
    let mut bad = Vec::new();
    let mut graph: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = BTreeMap::new();
    let mut modules: BTreeSet<Vec<String>> = BTreeSet::new();
    let mut parsed = Vec::new();
    for f in &files {
        let src = std::fs::read_to_string(f).expect("read source");
        let shown = f.strip_prefix(root()).unwrap_or(f).display().to_string();
        if !is_test_file(f) && src.lines().count() > MAX_FILE_LINES {
            bad.push(format!("{shown}: {} lines (at most {MAX_FILE_LINES})", src.lines().count()));
        }
        let code = blank(&src);
        for (name, line, len) in long_functions(&code) {
            bad.push(format!("{shown}:{line}: fn {name} has {len} lines (at most {MAX_FN_LINES})"));
        }
        let m = module_of(&src_dir, f);
        modules.insert(m.clone());
        parsed.push((f.clone(), m, code));
    }
    if crate_dir.ends_with("hil-sim") {
        // The binary's modules (`cli/`) are another crate: they reach the library as `hil_sim::`.
        parsed.retain(|(f, ..)| {
            !f.strip_prefix(&src_dir).is_ok_and(|r| r.starts_with("cli") || r == Path::new("main.rs"))
        });
    }
    for (f, m, code) in &parsed {
        if is_test_file(f) {
            continue;
        }
        let is_mod = f.file_name().is_some_and(|n| n == "mod.rs");
        for r in references(code, m, is_mod) {
            // The longest known module that prefixes the path (the rest are items).
            let target = (1..=r.len()).rev().map(|k| r[..k].to_vec()).find(|p| modules.contains(p));
            if let Some(t) = target {
                graph.entry(m.clone()).or_default().insert(t);
            }
        }
    }
    // Cycles between modules neither of which contains the other.
    let related = |a: &[String], b: &[String]| a.starts_with(b) || b.starts_with(a);
    let edges: Vec<(Vec<String>, Vec<String>)> = graph
        .iter()
        .flat_map(|(a, ts)| ts.iter().filter(|t| !related(a, t)).map(move |t| (a.clone(), t.clone())))
        .collect();
    // Lift every edge to the pair of sibling modules under the deepest common ancestor.
    let mut lifted: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = BTreeMap::new();
    for (a, b) in &edges {
        let common = a.iter().zip(b).take_while(|(x, y)| x == y).count();
        lifted.entry(a[..=common].to_vec()).or_default().insert(b[..=common].to_vec());
    }
    for (a, ts) in &lifted {
        for b in ts {
            if lifted.get(b).is_some_and(|back| back.contains(a)) && a < b {
                let why: Vec<String> = edges
                    .iter()
                    .filter(|(x, y)| (x.starts_with(a) && y.starts_with(b)) || (x.starts_with(b) && y.starts_with(a)))
                    .map(|(x, y)| format!("{} -> {}", x.join("::"), y.join("::")))
                    .collect();
                bad.push(format!(
                    "{}: import cycle between `{}` and `{}` ({})",
                    crate_dir.file_name().unwrap_or_default().to_string_lossy(),
                    a.join("::"),
                    b.join("::"),
                    why.join(", ")
                ));
            }
        }
    }
    bad
}

#[test]
fn model_core_files_functions_and_imports() {
    let bad = violations(&root().join("model-core"));
    assert!(bad.is_empty(), "model-core:\n{}", bad.join("\n"));
}

#[test]
fn hil_sim_files_functions_and_imports() {
    let bad = violations(&root().join("hil-sim"));
    assert!(bad.is_empty(), "hil-sim:\n{}", bad.join("\n"));
}

#[test]
fn the_checks_catch_what_they_look_for() {
    let long: String = std::iter::once("fn big() {\n".to_owned())
        .chain((0..130).map(|i| format!("    let a{i} = \"}}\"; // }}\n")))
        .chain(std::iter::once("}\n".to_owned()))
        .collect();
    let found = long_functions(&blank(&long));
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].2, 132);
    let short = "fn small() {\n    let c = '{';\n}\nfn other<'a>(x: &'a str) -> &'a str { x }\n";
    assert!(long_functions(&blank(short)).is_empty());
    let refs = references(
        &blank("use crate::io::recording::Recording;\nuse super::search::Scales; // crate::nope\n"),
        &["models".to_owned(), "bouc_wen".to_owned()],
        true,
    );
    assert!(refs.contains(&vec!["io".to_owned(), "recording".to_owned()]), "{refs:?}");
    assert!(refs.contains(&vec!["models".to_owned(), "search".to_owned()]), "{refs:?}");
    assert!(!refs.iter().any(|r| r.first().is_some_and(|w| w == "nope")), "{refs:?}");
}

/// Issue 17: the board's `memory.x` is at the repository root (the design card), and the
/// QEMU budget bench links with its own complete script, which includes no `memory.x`
/// (rust-lld, run in the workspace root, would take the board's).
#[test]
fn memory_x_is_at_the_root_and_the_bench_has_its_own_linker_script() {
    let r = root();
    let mem = std::fs::read_to_string(r.join("memory.x")).expect("memory.x at the repository root");
    let squeezed: String = mem.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(squeezed.contains("FLASH : ORIGIN = 0x08000000, LENGTH = 508K"), "{mem}");
    assert!(squeezed.contains("RAM : ORIGIN = 0x20000000, LENGTH = 96K"), "{mem}");
    assert!(!r.join("firmware/memory.x").exists(), "a second memory.x in firmware/");
    let bench = std::fs::read_to_string(r.join("firmware/budget-link.x")).expect("firmware/budget-link.x");
    assert!(!bench.lines().any(|l| l.trim_start().starts_with("INCLUDE memory.x")), "the bench includes memory.x");
    assert!(bench.contains("FLASH : ORIGIN = 0x00000000, LENGTH = 4M"), "mps2-an386 memory in the bench script");
    assert!(bench.contains("ENTRY(Reset)"), "a complete script (cortex-m-rt's link.x)");
}
