//! The scenario parser and its validation on arbitrary text.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|text: &str| {
    if let Ok(s) = hil_sim::sim::scenario::Scenario::parse(std::path::Path::new("s.toml"), text) {
        assert!(s.duration_s.is_finite() && s.duration_s > 0.0);
    }
});
