//! Issue 18, defect 10: a simulated recording carries `torque_true`; the diagnosis must not
//! "find" that the torque depends on its own truth or on a copy of the output.

mod common;
use common::hil_sim;

#[test]
fn diagnose_leaves_out_the_truth_and_copies_of_the_output() {
    let dir = std::env::temp_dir().join(format!("hil-sim-truth-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let rec = dir.join("rec.csv");
    let (code, _, err) = hil_sim(&[
        "simulate",
        "--effect",
        "aux_dependence",
        "--base",
        "algebraic",
        "--excitation",
        "noise",
        "--duration",
        "6",
        "--fs",
        "500",
        "--out",
        rec.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    // Add the truth (the torque slightly smoothed) and a scaled copy of the torque, as a
    // closed-loop recording carries `torque_true`.
    let text = std::fs::read_to_string(&rec).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let at = header.split(',').position(|c| c == "torque").unwrap();
    let mut out = format!("{header},torque_true,torque_copy\n");
    let mut prev = None;
    for l in lines {
        let y: f64 = l.split(',').nth(at).unwrap().parse().unwrap();
        let smooth = prev.map_or(y, |p: f64| 0.5 * (p + y));
        prev = Some(y);
        out.push_str(&format!("{l},{smooth},{}\n", 3.0 * y + 1.0));
    }
    std::fs::write(&rec, out).unwrap();
    let (code, out, err) = hil_sim(&["diagnose", rec.to_str().unwrap(), "--model", "algebraic", "--json"]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("channel `torque_true` is not used by the diagnosis"), "{err}");
    assert!(err.contains("channel `torque_copy` is not used by the diagnosis"), "{err}");
    assert!(!out.contains("torque_true") && !out.contains("torque_copy"), "{out}");
    let _ = std::fs::remove_dir_all(&dir);
}
