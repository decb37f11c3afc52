//! Issue 18, defect 4: a small compressed MAT-file that inflates to far more than its size
//! is refused from the array's declared size, before it is inflated.

use std::io::Write;
use std::path::Path;

use hil_sim::io::recording::Recording;

/// A level-5 MAT-file header (little-endian).
fn header() -> Vec<u8> {
    let mut h = format!("{:<116}", "MATLAB 5.0 MAT-file, written by the hil-sim tests").into_bytes();
    h.extend_from_slice(&[0; 8]);
    h.extend_from_slice(&0x0100u16.to_le_bytes());
    h.extend_from_slice(b"IM");
    h
}

fn tag(t: u32, n: u32) -> Vec<u8> {
    [t.to_le_bytes(), n.to_le_bytes()].concat()
}

/// One compressed element holding a 1×`n` double vector `name` filled with `value(i)`.
fn compressed_vector(name: &str, n: u32, value: impl Fn(u32) -> f64) -> Vec<u8> {
    let mut head = Vec::new();
    head.extend(tag(6, 8));
    head.extend([6u32.to_le_bytes(), 0u32.to_le_bytes()].concat()); // mxDOUBLE_CLASS
    head.extend(tag(5, 8));
    head.extend([1i32.to_le_bytes(), (n as i32).to_le_bytes()].concat());
    let mut nm = name.as_bytes().to_vec();
    head.extend(tag(1, nm.len() as u32));
    nm.resize(nm.len().div_ceil(8) * 8, 0);
    head.extend(nm);
    head.extend(tag(9, n * 8));
    let total = head.len() as u32 + n * 8;
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
    z.write_all(&tag(14, total)).unwrap();
    z.write_all(&head).unwrap();
    let mut chunk = Vec::with_capacity(1 << 16);
    for i in 0..n {
        chunk.extend_from_slice(&value(i).to_le_bytes());
        if chunk.len() >= 1 << 16 {
            z.write_all(&chunk).unwrap();
            chunk.clear();
        }
    }
    z.write_all(&chunk).unwrap();
    let data = z.finish().unwrap();
    let mut el = tag(15, data.len() as u32);
    el.extend(data);
    el
}

#[test]
fn a_compressed_bomb_is_refused_before_inflating() {
    // 100 MB of doubles in about 100 kB: over the 64 MiB + 4 × file size budget.
    let mut bytes = header();
    bytes.extend(compressed_vector("t", 12_500_000, |_| 0.0));
    assert!(bytes.len() < 1 << 20, "{} bytes", bytes.len());
    let err = Recording::parse(Path::new("bomb.mat"), &bytes).err().map(|e| e.to_string()).expect("the bomb was read");
    assert!(err.contains("bomb.mat") && err.contains("declares an array of"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
}

#[test]
fn an_honest_compressed_file_still_reads() {
    let mut bytes = header();
    bytes.extend(compressed_vector("t", 5000, |i| f64::from(i) * 1e-3));
    bytes.extend(compressed_vector("x", 5000, |i| f64::from(i % 17)));
    let rec = Recording::parse(Path::new("ok.mat"), &bytes).unwrap();
    assert_eq!(rec.len(), 5000);
    assert_eq!(rec.names(), ["t", "x"]);
}
