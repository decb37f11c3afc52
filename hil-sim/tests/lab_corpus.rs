//! Recordings as labs save them (issue 16, acceptance 1): every file in `tests/corpus/lab/`
//! (written by `make_lab.py` with SciPy, independently of this reader) opens with the right
//! flags and gives exactly the numbers of its clean CSV twin; the broken ones fail with one
//! line naming the file, the line or variable, and the problem.

mod common;

use std::path::{Path, PathBuf};

use hil_sim::io::recording::{Channels, Recording};

fn lab(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus/lab").join(name)
}

/// (file, time, x, F, aux, n16, constants given with the recording)
type Case = (&'static str, &'static str, &'static str, &'static str, &'static str, &'static str, bool);

const CASES: &[Case] = &[
    // MATLAB: a 100×3 matrix `x_F`, the voltage a scalar, beside a shorter `tout`, a NaN-holding
    // `theta_a` and a char array, none of which the channels use.
    ("matrix.mat", "Tout", "x_F:1", "x_F:2", "x_F:3", "n16", false),
    ("matrix_plain.mat", "Tout", "x_F:1", "x_F:2", "x_F:3", "n16", false),
    ("vectors_int16.mat", "t", "x", "F", "aux", "n16", false),
    // dSPACE ControlDesk: signals by name, the time is `X`; the voltage is given with --set.
    ("dspace.mat", "X", "x", "F", "aux", "n16", true),
    ("tab.txt", "t", "x", "F", "aux", "n16", true),
    ("space.dat", "t", "x", "F", "aux", "n16", true),
    ("semicolon_comma.csv", "t", "x", "F", "aux", "n16", true),
    ("crlf.csv", "t", "x", "F", "aux", "n16", true),
    ("no_header.txt", "1", "2", "3", "4", "5", true),
];

#[test]
fn every_layout_reads_the_numbers_of_its_twin() {
    let twin = Recording::read(&lab("twin.csv")).unwrap();
    let want = |n: &str| twin.channel(n).unwrap().to_vec();
    for &(file, time, x, f, aux, n16, given) in CASES {
        let mut rec = Recording::read(&lab(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        let ch = Channels {
            time: time.into(),
            input: x.into(),
            output: f.into(),
            command: Some("V".into()),
            set: if given { vec![("V".into(), 2.178)] } else { Vec::new() },
        };
        rec.apply_constants(&ch).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_eq!(rec.time(time).unwrap(), want("t").as_slice(), "{file}: time");
        for (name, twin_name) in [(x, "x"), (f, "F"), (aux, "aux"), (n16, "n16")] {
            assert_eq!(rec.channel(name).unwrap(), want(twin_name).as_slice(), "{file}: `{name}`");
        }
        assert!(rec.channel("V").unwrap().iter().all(|v| *v == 2.178), "{file}: V");
        // The whole pipeline takes it, the constant as the command.
        let p = hil_sim::ident::dataset::prepare_recording(rec, &ch, 0.7, false).unwrap();
        assert_eq!(p.data.command.as_ref().map(Vec::len), Some(100), "{file}");
    }
}

#[test]
fn skipped_variables_are_named_with_their_reason() {
    let rec = Recording::read(&lab("matrix.mat")).unwrap();
    let reason = |n: &str| rec.skipped.iter().find(|s| s.name == n).map(|s| s.reason.clone()).unwrap_or_default();
    assert!(reason("x_F").contains("100×3 matrix"), "{:?}", rec.skipped);
    assert!(reason("tout").contains("has 70 samples but `Tout` has 100"), "{:?}", rec.skipped);
    assert!(reason("theta_a").contains("sample 4: value is NaN"), "{:?}", rec.skipped);
    assert!(reason("notes").contains("char array"), "{:?}", rec.skipped);
    // CRLF: file lines are right (header line 1, first sample line 2).
    let rec = Recording::read(&lab("crlf.csv")).unwrap();
    assert_eq!((0..3).map(|i| rec.lines.get(i)).collect::<Vec<_>>(), [Some(2), Some(3), Some(4)]);
}

fn params(dir: &Path) -> PathBuf {
    let p = dir.join("p.json");
    std::fs::write(&p, r#"{"model":"algebraic","params":{"k":1,"c":0,"alpha":0,"t0":0}}"#).unwrap();
    p
}

#[test]
fn broken_files_fail_with_one_line_naming_file_place_and_problem() {
    let dir = common::scratch("lab-corpus");
    let p = params(&dir);
    let p = p.to_str().unwrap();
    let cases: &[(&str, &[&str], &[&str])] = &[
        (
            "err_semicolon.csv",
            &["--input", "x", "--output", "F"],
            &["err_semicolon.csv:5:", "`abc` is not a number", "semicolon-separated"],
        ),
        ("err_crlf.csv", &["--input", "x", "--output", "F"], &["err_crlf.csv:7:", "NaN"]),
        ("err_mixed.txt", &["--input", "x", "--output", "F"], &["err_mixed.txt:2:", "separated by spaces"]),
        (
            "matrix.mat",
            &["--time", "Tout", "--input", "x_F", "--output", "x_F:2"],
            &["matrix.mat", "variable `x_F` is a 100×3 matrix", "`x_F:K`"],
        ),
        (
            "matrix.mat",
            &["--time", "Tout", "--input", "x_F:1", "--output", "theta_a"],
            &["matrix.mat", "variable `theta_a`, sample 4: value is NaN"],
        ),
        (
            "matrix.mat",
            &["--time", "tout", "--input", "x_F:1", "--output", "x_F:2"],
            &["matrix.mat", "variable `tout` has 70 samples but `Tout` has 100"],
        ),
        (
            "dspace.mat",
            &["--time", "X", "--input", "x", "--output", "F", "--command", "V"],
            &["dspace.mat", "no column `V`"],
        ),
        (
            "no_header.txt",
            &["--input", "x", "--output", "F"],
            &["no_header.txt", "no column `t`", "no header row", "numbered from 1"],
        ),
        ("twin.csv", &["--input", "x", "--output", "F", "--set", "x=1"], &["twin.csv", "constant", "channel `x`"]),
    ];
    for (file, flags, needles) in cases {
        let f = lab(file);
        let mut args = vec!["replay", f.to_str().unwrap(), "--params", p, "--json"];
        args.extend_from_slice(flags);
        let (code, out, err) = common::hil_sim(&args);
        assert_ne!(code, 0, "{file} {flags:?}: exit 0");
        assert!(out.is_empty(), "{file}: stdout {out}");
        assert_eq!(err.trim_end().lines().count(), 1, "{file} {flags:?}: {err}");
        for n in *needles {
            assert!(err.contains(n), "{file} {flags:?}: no `{n}` in {err}");
        }
    }
}
