//! Fuzzing the recording readers with proptest: arbitrary bytes and mutated valid files
//! (bytes flipped, cut, inserted) go into the CSV and MAT parsers straight from memory.
//! Neither may panic; each returns either a consistent recording (equally long finite
//! columns, one line number per sample, at least 3 samples) or a typed error whose message
//! is one line naming the file. What parses also goes through the quality check.
//!
//! proptest rather than cargo-fuzz: cargo-fuzz needs a nightly toolchain, which this
//! project does not install (stable 1.95 only). The case counts keep the whole file at a
//! few seconds in a release build.

use std::path::Path;

use hil_sim::io::recording::{Recording, RecordingError};
use proptest::prelude::*;

const GOOD_CSV: &[u8] =
    b"\"t\",\"b\",\"fs\",\"torque\",\n0,0.1,1000,1.5,\n0.001,0.2,,1.6,\n0.002,0.3,,1.7,\n0.003,0.25,,1.65,\n";
const GOOD_MAT: &[u8] = include_bytes!("corpus/good.mat");
const GOOD_MAT_Z: &[u8] = include_bytes!("corpus/good_compressed.mat");

fn consistent(r: &Result<Recording, RecordingError>, name: &str) -> Result<(), TestCaseError> {
    match r {
        Ok(rec) => {
            let n = rec.len();
            prop_assert!(n >= 3);
            prop_assert_eq!(rec.lines.len(), n);
            for c in &rec.columns {
                prop_assert_eq!(c.values.len(), n, "column {}", c.name);
                prop_assert!(c.values.iter().all(|v| v.is_finite()));
            }
            prop_assert!(rec.constants.iter().all(|c| c.1.is_finite()));
            // Whatever parses also goes through the quality check without panicking.
            let _ = hil_sim::quality::check(rec, &hil_sim::io::recording::Channels::default());
        }
        Err(e) => {
            let m = e.to_string();
            prop_assert!(!m.contains('\n') && !m.contains('\r'), "two lines: {m:?}");
            prop_assert!(m.starts_with(name), "{m}");
        }
    }
    Ok(())
}

#[derive(Clone, Debug)]
enum Edit {
    Flip(usize, u8),
    Cut(usize),
    Insert(usize, Vec<u8>),
    Set(usize, u8),
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (any::<usize>(), 1..=255u8).prop_map(|(i, b)| Edit::Flip(i, b)),
        any::<usize>().prop_map(Edit::Cut),
        (any::<usize>(), prop::collection::vec(any::<u8>(), 1..8)).prop_map(|(i, v)| Edit::Insert(i, v)),
        (
            any::<usize>(),
            prop_oneof![Just(0u8), Just(0xFF), Just(b','), Just(b'\n'), Just(b'"'), Just(b'-'), Just(b'.')]
        )
            .prop_map(|(i, b)| Edit::Set(i, b)),
    ]
}

fn mutate(base: &[u8], edits: &[Edit]) -> Vec<u8> {
    let mut v = base.to_vec();
    for e in edits {
        if v.is_empty() {
            break;
        }
        match e {
            Edit::Flip(i, b) => {
                let i = i % v.len();
                v[i] ^= b;
            }
            Edit::Cut(i) => v.truncate(i % v.len()),
            Edit::Insert(i, bytes) => {
                let i = i % (v.len() + 1);
                v.splice(i..i, bytes.iter().copied());
            }
            Edit::Set(i, b) => {
                let i = i % v.len();
                v[i] = *b;
            }
        }
    }
    v
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3000, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_bytes(bytes in prop::collection::vec(any::<u8>(), 0..600)) {
        consistent(&Recording::parse_csv(Path::new("a.csv"), &bytes), "a.csv")?;
        consistent(&Recording::parse_mat(Path::new("a.mat"), &bytes), "a.mat")?;
        // With a MAT header in front, the bytes reach the element parser.
        let mut mat = GOOD_MAT[..128].to_vec();
        mat.extend_from_slice(&bytes);
        consistent(&Recording::parse(Path::new("h.mat"), &mat), "h.mat")?;
    }

    #[test]
    fn mutated_csv(edits in prop::collection::vec(edit(), 1..5)) {
        let bytes = mutate(GOOD_CSV, &edits);
        consistent(&Recording::parse_csv(Path::new("m.csv"), &bytes), "m.csv")?;
    }

    #[test]
    fn mutated_mat(edits in prop::collection::vec(edit(), 1..5)) {
        let bytes = mutate(GOOD_MAT, &edits);
        consistent(&Recording::parse_mat(Path::new("m.mat"), &bytes), "m.mat")?;
    }

    #[test]
    fn mutated_compressed_mat(edits in prop::collection::vec(edit(), 1..4)) {
        let bytes = mutate(GOOD_MAT_Z, &edits);
        consistent(&Recording::parse_mat(Path::new("z.mat"), &bytes), "z.mat")?;
    }
}

/// The unmutated inputs parse (so the mutations start from valid files).
#[test]
fn seeds_are_valid() {
    assert_eq!(Recording::parse_csv(Path::new("s.csv"), GOOD_CSV).unwrap().len(), 4);
    assert_eq!(Recording::parse_mat(Path::new("s.mat"), GOOD_MAT).unwrap().len(), 50);
    assert_eq!(Recording::parse_mat(Path::new("s.mat"), GOOD_MAT_Z).unwrap().len(), 50);
}
