//! The CSV/text reader on arbitrary bytes: no panic; what parses is consistent.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(rec) = hil_sim::io::recording::Recording::parse_csv(std::path::Path::new("f.csv"), data) {
        assert!(rec.columns.iter().all(|c| c.values.len() == rec.len() && c.values.iter().all(|v| v.is_finite())));
        let _ = hil_sim::quality::check(&rec, &hil_sim::io::recording::Channels::default());
    }
});
