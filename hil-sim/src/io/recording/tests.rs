use super::*;

fn parse(s: &str) -> Result<Recording, RecordingError> {
    Recording::parse_csv(Path::new("rec.csv"), s.as_bytes())
}

#[test]
fn written_csv_reads_back_the_same_values() {
    let col = |name: &str, values: Vec<f64>| Column { name: name.into(), values };
    let columns = vec![col("t", vec![0.0, 0.0005, 0.001]), col("b", vec![0.1 + 0.2, -1e-7, 12345.678901])];
    let rec = Recording::from_columns(Path::new("mem"), columns, vec![("fs".into(), 2000.0)]);
    let mut out = Vec::new();
    rec.write_csv(&mut out).unwrap();
    let text = String::from_utf8(out).unwrap();
    assert!(text.starts_with("t,b,fs\n0,0.30000000000000004,2000\n"), "{text}");
    let back = parse(&text).unwrap();
    assert_eq!(back.columns, rec.columns);
    assert_eq!(back.constants, rec.constants);
}

#[test]
fn reads_dyke_quirks() {
    let r = parse("\"t\",\"D\",\"fs\",\"F\",\n0,1.5,3004.8,10,\n0.1,1.6,,11,\n0.2,1.7,,12,\n").unwrap();
    assert_eq!(r.names(), vec!["t", "D", "F"]);
    assert_eq!(r.constants, vec![("fs".to_owned(), 3004.8)]);
    assert_eq!(r.channel("F").unwrap(), &[10.0, 11.0, 12.0]);
    assert!((r.sample_interval("t").unwrap() - 0.1).abs() < 1e-12);
}

#[test]
fn errors_name_line_and_reason() {
    let msg = |s: &str| parse(s).unwrap_err().to_string();
    assert!(msg("").contains("empty"));
    assert!(msg("t,x\n").contains("empty"));
    let m = msg("t,x\n0,1\n0.1,abc\n0.2,3\n");
    assert!(m.contains("rec.csv:3") && m.contains("`abc` is not a number"), "{m}");
    // A file whose first data row is not numbers is not known to be a recording: its
    // content is never quoted (a manifest could name /etc/shadow).
    let m = msg("root:*:19000:0:99999:7:::\ndaemon:*:19000:0:99999:7:::\nbin:*:1:2\n");
    assert!(m.contains("rec.csv:2: field 1 is not a number") && m.contains("content is not shown"), "{m}");
    assert!(!m.contains("root") && !m.contains("daemon") && !m.contains("19000"), "{m}");
    let m = msg("a,a\nsecret,1\n2,3\n");
    assert!(!m.contains("secret") && !m.contains("`a`"), "{m}");
    let m = msg("t,x\n0,1\n0.1,NaN\n0.2,3\n");
    assert!(m.contains("rec.csv:3") && m.contains("NaN"), "{m}");
    let m = msg("t,x\n0,1\n0.1,\n0.2,3\n");
    assert!(m.contains("rec.csv:3") && m.contains("no value"), "{m}");
    let r = parse("t,x\n0,1\n0.1,2\n0.1,3\n").unwrap();
    let m = r.time("t").unwrap_err().to_string();
    assert!(m.contains("rec.csv:4") && m.contains("does not increase"), "{m}");
    let m = r.channel("F").unwrap_err().to_string();
    assert!(m.contains("no column `F`") && m.contains("t, x"), "{m}");
}

#[test]
fn reads_the_real_dyke_file() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/dyke/ranran_50.csv");
    let r = Recording::read_csv(&path).unwrap();
    assert_eq!(r.len(), 74_068);
    assert_eq!(r.names(), vec!["t", "A", "D", "Y", "V", "F"]);
    assert!(r.time("t").is_ok());
    let fs = r.constants.iter().find(|(n, _)| n == "fs").map(|c| c.1).unwrap();
    assert!((1.0 / r.sample_interval("t").unwrap() - fs).abs() < 1.0);
}

fn corpus(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus").join(name)
}

#[test]
fn reads_mat_files_plain_and_compressed() {
    let a = Recording::read(&corpus("good.mat")).unwrap();
    let b = Recording::read(&corpus("good_compressed.mat")).unwrap();
    assert_eq!(a.format, Format::Mat);
    assert_eq!(a.names(), vec!["t", "b", "torque", "speed", "temperature"]);
    assert_eq!(a.constants, vec![("fs".to_owned(), 1000.0)]);
    assert_eq!(a.len(), 50);
    assert_eq!(a.columns, b.columns);
    assert!((a.sample_interval("t").unwrap() - 0.001).abs() < 1e-12);
    assert_eq!(a.channel("temperature").unwrap()[3], 23.0);
    assert!((a.channel("speed").unwrap()[49] - 10.0).abs() < 1e-6);
    let ch = Channels::default();
    assert_eq!(a.auxiliary(&ch), vec!["speed", "temperature"]);
    assert_eq!(a.place(0, 2), format!("{}: samples 1-3", corpus("good.mat").display()));
}

#[test]
fn mat_errors_name_file_variable_and_sample() {
    let msg = |n: &str| Recording::read(&corpus(n)).unwrap_err().to_string();
    let m = msg("truncated.mat");
    assert!(m.contains("truncated.mat") && m.contains("truncated MAT-file"), "{m}");
    // A variable that cannot be a channel is skipped; asking for it gives the reason.
    let used = |n: &str, var: &str| {
        let r = Recording::read(&corpus(n)).unwrap();
        assert!(r.channel("t").is_ok() && r.skipped.iter().any(|s| s.name == var), "{n}: {:?}", r.skipped);
        r.channel(var).unwrap_err().to_string()
    };
    let m = used("matrix_shape.mat", "torque");
    assert!(m.contains("variable `torque` is a 3×4 matrix") && m.contains("`torque:K`"), "{m}");
    let m = used("length_mismatch.mat", "torque");
    assert!(m.contains("variable `torque` has 40 samples but `t` has 50"), "{m}");
    let m = used("nan.mat", "torque");
    assert!(m.contains("variable `torque`, sample 17: value is NaN"), "{m}");
    let m = used("char_variable.mat", "notes");
    assert!(m.contains("variable `notes` is a char array"), "{m}");
    let m = msg("garbage.bin");
    assert!(m.contains("garbage.bin") && m.contains("binary data"), "{m}");
    let r = Recording::read(&corpus("time_not_increasing.mat")).unwrap();
    let m = r.time("t").unwrap_err().to_string();
    assert!(m.contains("time_not_increasing.mat: sample 31: time"), "{m}");
    // A `.mat` name with text inside is judged as a MAT-file.
    let m = Recording::parse(Path::new("x.mat"), b"t,b\n0,1\n").unwrap_err().to_string();
    assert!(m.contains("x.mat") && m.contains("shorter than the 128-byte"), "{m}");
    // Big-endian files are read too: the plain file with every field byte-swapped.
    let le = std::fs::read(corpus("good.mat")).unwrap();
    let be = to_big_endian(&le);
    let r = Recording::parse(Path::new("be.mat"), &be).unwrap();
    assert_eq!(r.columns, Recording::parse(Path::new("le.mat"), &le).unwrap().columns);
}

/// Byte-swap an uncompressed little-endian level-5 file (tags, flags, dims and data).
fn to_big_endian(le: &[u8]) -> Vec<u8> {
    fn width(t: u32) -> usize {
        match t {
            3 | 4 => 2,
            5..=7 => 4,
            9 | 12 | 13 => 8,
            _ => 1,
        }
    }
    fn elements(src: &[u8], out: &mut Vec<u8>) {
        let mut pos = 0;
        while pos + 8 <= src.len() {
            let first = u32::from_le_bytes(src[pos..pos + 4].try_into().unwrap());
            let (t, n, head, data_at) = if first >> 16 != 0 {
                (first & 0xFFFF, (first >> 16) as usize, 4, pos + 4)
            } else {
                (first, u32::from_le_bytes(src[pos + 4..pos + 8].try_into().unwrap()) as usize, 8, pos + 8)
            };
            if head == 4 {
                out.extend_from_slice(&((n as u32) << 16 | t).to_be_bytes());
            } else {
                out.extend_from_slice(&t.to_be_bytes());
                out.extend_from_slice(&(n as u32).to_be_bytes());
            }
            let data = &src[data_at..data_at + n];
            if t == 14 {
                elements(data, out);
            } else {
                let w = width(t);
                for c in data.chunks(w) {
                    out.extend(c.iter().rev());
                }
            }
            let padded = if head == 4 { 4 } else { n.div_ceil(8) * 8 };
            out.extend(std::iter::repeat_n(0u8, padded - n));
            pos = data_at + padded;
        }
    }
    let mut out = le[..128].to_vec();
    out[124] = 0x01;
    out[125] = 0x00;
    out[126] = b'M';
    out[127] = b'I';
    elements(&le[128..], &mut out);
    out
}

/// A level-5 element: tag (type, size) then the data padded to 8 bytes.
fn mat_element(t: u32, data: &[u8]) -> Vec<u8> {
    let mut out = t.to_le_bytes().to_vec();
    out.extend((data.len() as u32).to_le_bytes());
    out.extend_from_slice(data);
    out.resize(8 + data.len().div_ceil(8) * 8, 0);
    out
}

/// A struct array with no fields but a huge element count: nothing to read per element, so
/// the count must not become an allocation or a loop (it did: a capacity overflow panic).
#[test]
fn a_struct_with_no_fields_and_a_huge_count_is_read_without_allocating() {
    let mut flags = 2u32.to_le_bytes().to_vec(); // class 2: struct
    flags.extend([0; 4]);
    let mut dims = i32::MAX.to_le_bytes().to_vec();
    dims.extend(i32::MAX.to_le_bytes());
    let mut payload = mat_element(6, &flags);
    payload.extend(mat_element(5, &dims));
    payload.extend(mat_element(1, b"Y"));
    payload.extend(mat_element(5, &8i32.to_le_bytes()));
    payload.extend(mat_element(1, b""));
    let mut bytes = format!("{:<116}", "MATLAB 5.0 MAT-file").into_bytes();
    bytes.extend([0u8; 8]);
    bytes.extend(0x0100u16.to_le_bytes());
    bytes.extend(b"IM");
    bytes.extend(mat_element(14, &payload));
    // The file holds no channel: refused in one line naming it, after reading the struct.
    let e = Recording::parse(Path::new("s.mat"), &bytes).unwrap_err().to_string();
    assert!(e.contains("s.mat") && !e.contains("capacity"), "{e}");
}
