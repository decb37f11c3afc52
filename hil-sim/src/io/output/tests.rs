#![allow(clippy::unwrap_used)]
use super::*;

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hil-sim-output-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn writes_through_a_temporary_file_and_leaves_none() {
    let d = tmp("plain");
    write(&d.join("sub/a.txt"), "one").unwrap();
    write(&d.join("sub/a.txt"), "two").unwrap();
    assert_eq!(std::fs::read_to_string(d.join("sub/a.txt")).unwrap(), "two");
    assert_eq!(std::fs::read_dir(d.join("sub")).unwrap().count(), 1, "a temporary file was left");
    let e = write_with(&d.join("sub/b.txt"), |_| Err(std::io::Error::other("boom"))).unwrap_err();
    assert!(e.to_string().contains("boom"));
    assert_eq!(std::fs::read_dir(d.join("sub")).unwrap().count(), 1, "a failed write left a file");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn an_input_is_never_an_output() {
    let d = tmp("input");
    let input = d.join("rec.csv");
    std::fs::write(&input, "t,x\n0,1\n").unwrap();
    note_input(&input);
    let e = write(&input, "gone").unwrap_err();
    assert!(matches!(e, OutputError::SameAsInput { .. }), "{e}");
    // The same file by another spelling.
    let e = write(&d.join(".").join("rec.csv"), "gone").unwrap_err();
    assert!(matches!(e, OutputError::SameAsInput { .. }), "{e}");
    #[cfg(unix)]
    {
        std::fs::hard_link(&input, d.join("hard.csv")).unwrap();
        let e = write(&d.join("hard.csv"), "gone").unwrap_err();
        assert!(matches!(e, OutputError::SameAsInput { .. }), "{e}");
    }
    assert_eq!(std::fs::read_to_string(&input).unwrap(), "t,x\n0,1\n");
    write(&d.join("other.csv"), "fine").unwrap();
    let _ = std::fs::remove_dir_all(&d);
}

#[cfg(unix)]
#[test]
fn a_planted_symlink_is_refused() {
    let d = tmp("link");
    let outside = d.join("outside.txt");
    std::fs::write(&outside, "keep").unwrap();
    std::fs::create_dir_all(d.join("out")).unwrap();
    std::os::unix::fs::symlink(&outside, d.join("out/index.html")).unwrap();
    let e = write(&d.join("out/index.html"), "evil").unwrap_err();
    assert!(matches!(e, OutputError::Symlink { .. }) && e.to_string().contains("symbolic link"), "{e}");
    assert_eq!(std::fs::read_to_string(&outside).unwrap(), "keep");
    let _ = std::fs::remove_dir_all(&d);
}
