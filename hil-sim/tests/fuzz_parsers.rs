//! Fuzzing the parameter-file and scenario parsers with proptest (issue 18): arbitrary
//! text and mutated valid files go into `ParamsFile::parse` (+ the model's validation,
//! `flat`) and `Scenario::parse` (+ its validation) straight from memory. Neither may
//! panic; each gives either a validated result (finite parameters of the right count, a
//! scenario whose numbers are finite and in range) or a typed error of one line naming the
//! file. proptest rather than cargo-fuzz: cargo-fuzz needs a nightly toolchain, which this
//! project does not install (see fuzz_readers.rs).

use std::path::Path;

use hil_sim::io::params_file::ParamsFile;
use hil_sim::sim::scenario::Scenario;
use proptest::prelude::*;

const SPENCER: &str = include_str!("../params/spencer_dyke_1997.json");

fn one_line(msg: &str, name: &str) -> Result<(), TestCaseError> {
    prop_assert!(!msg.contains('\n') && !msg.contains('\r'), "two lines: {msg:?}");
    prop_assert!(msg.starts_with(name), "{msg}");
    Ok(())
}

fn params(text: &str) -> Result<(), TestCaseError> {
    let path = Path::new("p.json");
    match ParamsFile::parse(path, text) {
        Ok(f) => match f.flat(path) {
            Ok(v) => {
                let n = model_core::MODELS.iter().find(|m| m.id == f.model).map(|m| m.n_params);
                prop_assert_eq!(Some(v.len()), n, "{} parameters for {}", v.len(), f.model);
                prop_assert!(v.iter().all(|x| x.is_finite()), "{v:?}");
            }
            Err(e) => one_line(&e.to_string(), "p.json")?,
        },
        Err(e) => one_line(&e.to_string(), "p.json")?,
    }
    Ok(())
}

fn scenario(text: &str) -> Result<(), TestCaseError> {
    let path = Path::new("s.toml");
    match Scenario::parse(path, text) {
        Ok(s) => {
            prop_assert!(s.duration_s.is_finite() && s.duration_s > 0.0, "{}", s.duration_s);
            prop_assert!(s.control_hz.is_finite() && s.control_hz > 0.0);
            prop_assert!(s.record_hz.is_finite() && s.record_hz > 0.0);
            prop_assert!(s.reference.lo.is_finite() && s.reference.hi.is_finite());
        }
        Err(e) => one_line(&e.to_string(), "s.toml")?,
    }
    Ok(())
}

/// A valid scenario file to mutate.
fn scenario_text() -> String {
    toml::to_string(&Scenario::builtin("multisine").unwrap()).unwrap()
}

/// Replace the `k`-th number in `text` by `with`.
fn replace_number(text: &str, k: usize, with: &str) -> String {
    let mut spans = Vec::new();
    let b = text.as_bytes();
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_digit()
            && (i == 0 || !b[i - 1].is_ascii_alphanumeric() && b[i - 1] != b'_' && b[i - 1] != b'[')
        {
            let start = if i > 0 && b[i - 1] == b'-' { i - 1 } else { i };
            let mut j = i;
            while j < b.len() && (b[j].is_ascii_alphanumeric() || matches!(b[j], b'.' | b'-' | b'+')) {
                j += 1;
            }
            spans.push((start, j));
            i = j;
        } else {
            i += 1;
        }
    }
    if spans.is_empty() {
        return text.to_owned();
    }
    let (a, z) = spans[k % spans.len()];
    format!("{}{with}{}", &text[..a], &text[z..])
}

fn hostile() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("nan".to_owned()),
        Just("inf".to_owned()),
        Just("-inf".to_owned()),
        Just("1e308".to_owned()),
        Just("-1e308".to_owned()),
        Just("1e999".to_owned()),
        Just("0".to_owned()),
        Just("-1".to_owned()),
        Just("1e-320".to_owned()),
        Just("9223372036854775807".to_owned()),
        Just("\"x\"".to_owned()),
        Just("[]".to_owned()),
        any::<f64>().prop_map(|v| format!("{v:e}")),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_text(text in "\\PC{0,300}") {
        params(&text)?;
        scenario(&text)?;
    }

    #[test]
    fn parameter_file_with_a_hostile_number(k in any::<usize>(), with in hostile()) {
        params(&replace_number(SPENCER, k, &with))?;
    }

    #[test]
    fn scenario_with_a_hostile_number(k in any::<usize>(), with in hostile()) {
        scenario(&replace_number(&scenario_text(), k, &with))?;
    }

    #[test]
    fn truncated_files(cut in any::<usize>()) {
        let s = scenario_text();
        let c = (cut % (s.len() + 1)).min(s.len());
        if s.is_char_boundary(c) {
            scenario(&s[..c])?;
        }
        let c = cut % (SPENCER.len() + 1);
        if SPENCER.is_char_boundary(c) {
            params(&SPENCER[..c])?;
        }
    }
}

#[test]
fn the_seed_files_are_valid() {
    params(SPENCER).unwrap();
    scenario(&scenario_text()).unwrap();
    assert!(ParamsFile::parse(Path::new("p.json"), SPENCER).unwrap().flat(Path::new("p.json")).is_ok());
    assert!(Scenario::parse(Path::new("s.toml"), &scenario_text()).is_ok());
}
