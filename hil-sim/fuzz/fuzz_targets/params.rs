//! The parameter-file parser and the model's validation on arbitrary text.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|text: &str| {
    let path = std::path::Path::new("p.json");
    if let Ok(f) = hil_sim::io::params_file::ParamsFile::parse(path, text) {
        if let Ok(v) = f.flat(path) {
            assert!(v.iter().all(|x| x.is_finite()));
        }
    }
});
