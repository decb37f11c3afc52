//! The MAT-file reader on arbitrary bytes (after a valid header half the time, unless the
//! input is already a MAT-file, as the seeds from the test corpus are): no panic, no
//! allocation beyond its budget; what parses is consistent.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut bytes = data.to_vec();
    if !data.starts_with(b"MATLAB") && data.first().is_some_and(|b| b & 1 == 1) {
        let mut h = format!("{:<116}", "MATLAB 5.0 MAT-file").into_bytes();
        h.extend([0u8; 8]);
        h.extend(0x0100u16.to_le_bytes());
        h.extend(b"IM");
        h.extend_from_slice(&data[1..]);
        bytes = h;
    }
    if let Ok(rec) = hil_sim::io::recording::Recording::parse_mat(std::path::Path::new("f.mat"), &bytes) {
        assert!(rec.columns.iter().all(|c| c.values.len() == rec.len() && c.values.iter().all(|v| v.is_finite())));
    }
});
