//! Hostile numbers on the command line and in the files (issue 18): each gives a one-line
//! error naming the field and the problem, or a correct result; never a score over no
//! sample, a hang, or a file with NaN in it. Inputs are generated here.

use std::path::{Path, PathBuf};

mod common;
use common::{hil_sim_within, scratch};

/// Longest any of these runs may take, s: each is refused from its numbers, before work.
const DEADLINE_S: u64 = 60;

fn hil_sim(args: &[&str]) -> (i32, String, String) {
    hil_sim_within(args, DEADLINE_S)
}

/// A 3 s recording at 1 kHz, `t,b,torque`, with `row` replacing the generated rows where it
/// returns `Some`.
fn recording(dir: &Path, name: &str, mut row: impl FnMut(usize, f64, f64, f64) -> Option<String>) -> PathBuf {
    let mut s = String::from("t,b,torque\n");
    for i in 0..3000 {
        let t = i as f64 / 1000.0;
        let b = 0.5 * (2.0 * std::f64::consts::PI * 1.3 * t).sin() + 0.2 * (2.0 * std::f64::consts::PI * 3.1 * t).sin();
        let y = 300.0 * b + 20.0 * (50.0 * b).tanh();
        s += &row(i, t, b, y).unwrap_or_else(|| format!("{t:.4},{b:.6},{y:.5}"));
        s.push('\n');
    }
    let p = dir.join(name);
    std::fs::write(&p, s).unwrap();
    p
}

fn plain(dir: &Path) -> PathBuf {
    recording(dir, "rec.csv", |_, _, _, _| None)
}

/// One line on stderr, a non-zero exit, and every `needles` in it.
fn refused(r: &(i32, String, String), needles: &[&str]) {
    let (code, out, err) = r;
    assert_ne!(*code, 0, "exit 0; stdout {out}");
    assert_eq!(err.trim().lines().count(), 1, "not one line: {err}");
    for n in needles {
        assert!(err.contains(n), "`{n}` not in {err}");
    }
}

#[test]
fn a_delay_longer_than_the_recording_is_refused_not_scored_perfect() {
    let d = scratch("delay");
    let rec = plain(&d);
    let rec = rec.to_str().unwrap();
    for delay in ["1e9", "-1e9", "2.5", "-2.5", "1e300,0"] {
        let r = hil_sim(&["fit", rec, "--model", "algebraic", &format!("--delay={delay}")]);
        refused(&r, &["delay"]);
    }
    // Replay with the delay in the parameter file.
    let save = d.join("saved");
    let r = hil_sim(&["fit", rec, "--model", "algebraic", "--delay", "off", "--save", save.to_str().unwrap()]);
    assert_eq!(r.0, 0, "{}", r.2);
    let params = std::fs::read_to_string(save.join("algebraic.json")).unwrap();
    for delay in ["1e9", "-5", "-1e300"] {
        let p = d.join(format!("p{delay}.json"));
        std::fs::write(&p, params.replacen("\"model\"", &format!("\"delay_s\": {delay}, \"model\""), 1)).unwrap();
        let r = hil_sim(&["replay", rec, "--params", p.to_str().unwrap(), "--json"]);
        refused(&r, &["rec.csv", "delay", "no sample"]);
    }
    // A delay inside the recording still scores.
    let p = d.join("ok.json");
    std::fs::write(&p, params.replacen("\"model\"", "\"delay_s\": 0.001, \"model\"", 1)).unwrap();
    let r = hil_sim(&["replay", rec, "--params", p.to_str().unwrap(), "--json"]);
    assert_eq!(r.0, 0, "{}", r.2);
    assert!(r.1.contains("\"n\": 2999"), "{}", r.1);
}

#[test]
fn a_loop_duration_that_scores_nothing_is_refused() {
    for dur in ["0", "nan", "-1", "0.4"] {
        let r = hil_sim(&["loop", "--scenario", "multisine", &format!("--duration={dur}")]);
        refused(&r, &["duration"]);
    }
    let r = hil_sim(&["loop", "--scenario", "multisine", "--control-hz=0"]);
    refused(&r, &["control"]);
    // A duration the scenario would not use is refused, not ignored.
    for scenario in ["steps", "sweep", "heating", "faults"] {
        let r = hil_sim(&["loop", "--scenario", scenario, "--duration=8e11"]);
        refused(&r, &["--duration", "multisine only", scenario]);
    }
}

#[test]
fn sizes_are_bounded_from_the_numbers_before_any_work() {
    for dur in ["inf", "1e9", "1e300", "200"] {
        let r = hil_sim(&["loop", "--scenario", "multisine", &format!("--duration={dur}")]);
        refused(&r, &["duration"]);
    }
    let r = hil_sim(&["loop", "--scenario", "heating", "--control-hz=1e9"]);
    refused(&r, &["control steps"]);
    let d = scratch("sizes");
    let cases = [
        ("duration_s = 1e9\n", "duration_s"),
        ("duration_s = 1e6\n", "duration_s"),
        ("duration_s = 2.0\n[clutch.magnetic]\nn_play = 100000000\n", "clutch.magnetic.n_play"),
        ("duration_s = 2.0\n[clutch]\npwm_substeps = 100000000\n", "clutch.pwm_substeps"),
        ("duration_s = 2.0\n[clutch.coil]\npwm_hz = 1e12\n", "clutch.coil.pwm_hz"),
        ("duration_s = 90.0\ncontrol_hz = 100000.0\n", "control steps"),
    ];
    for (i, (toml, field)) in cases.iter().enumerate() {
        let p = d.join(format!("s{i}.toml"));
        std::fs::write(&p, toml).unwrap();
        let out = d.join(format!("s{i}.csv"));
        let r = hil_sim(&["simulate", "--scenario", p.to_str().unwrap(), "--out", out.to_str().unwrap()]);
        refused(&r, &[&format!("s{i}.toml"), field]);
        assert!(!out.exists(), "{toml}: wrote {}", out.display());
        let r = hil_sim(&["loop", "--scenario", "steps", "--clutch", p.to_str().unwrap()]);
        refused(&r, &[&format!("s{i}.toml"), field]);
    }
}

#[test]
fn simulate_refuses_unphysical_scenarios_and_writes_no_absurd_file() {
    let d = scratch("physical");
    let mut cases: Vec<(String, &str)> = Vec::new();
    // Every float of the clutch tables, NaN and infinite in turn (generated from the field list).
    for (table, field) in
        [("clutch.fluid", "tau_sat"), ("clutch.fluid", "gap"), ("clutch.thermal", "r_th"), ("clutch", "initial_c")]
    {
        for v in ["nan", "inf", "-inf"] {
            cases.push((format!("duration_s = 2.0\n[{table}]\n{field} = {v}\n"), field));
        }
    }
    cases.push(("duration_s = 2.0\n[clutch.fluid]\ngap = 1e-300\n".into(), "clutch.fluid.gap"));
    cases.push(("duration_s = 2.0\n[clutch]\ninitial_c = -300.0\n".into(), "clutch.initial_c"));
    cases.push(("duration_s = 2.0\n[clutch]\nambient_c = -273.15\n".into(), "clutch.ambient_c"));
    cases.push(("duration_s = 1e-9\n".into(), "duration_s"));
    // Finite but absurd: the run diverges, and the recording is refused.
    cases.push(("duration_s = 2.0\n[clutch.fluid]\neta40 = 1e300\n".into(), "diverged"));
    for (i, (toml, needle)) in cases.iter().enumerate() {
        let p = d.join(format!("p{i}.toml"));
        std::fs::write(&p, toml).unwrap();
        let out = d.join(format!("p{i}.csv"));
        let r = hil_sim(&["simulate", "--scenario", p.to_str().unwrap(), "--out", out.to_str().unwrap()]);
        refused(&r, &[&format!("p{i}.toml"), needle]);
        assert!(!out.exists(), "{toml}: wrote {}", out.display());
    }
}

#[test]
fn one_absurd_sample_is_a_spike_naming_its_line_and_the_fit_uses_the_rest() {
    let d = scratch("absurd");
    // Positions in the training part, the held-out part and the first row; absurd values
    // of both signs.
    for (k, (row, value)) in [(1499usize, "1e308"), (2500, "-1e308"), (0, "1e200"), (2999, "-3e250")].iter().enumerate()
    {
        let rec = recording(&d, &format!("absurd{k}.csv"), |i, t, b, _| {
            (i == *row).then(|| format!("{t:.4},{b:.6},{value}"))
        });
        let r = hil_sim(&["fit", rec.to_str().unwrap(), "--model", "algebraic", "--delay", "off", "--json"]);
        assert_eq!(r.0, 0, "{}", r.2);
        // The header is line 1: row i is on line i + 2.
        assert!(r.2.contains(&format!("absurd{k}.csv:{}", row + 2)), "{}", r.2);
        assert!(!r.2.contains("clipped"), "{}", r.2);
        assert!(!r.1.contains("null") && !r.1.to_lowercase().contains("nan"), "{}", r.1);
        let v: serde_json::Value = serde_json::from_str(&r.1).unwrap();
        let fit = &v["results"][0];
        for part in ["train", "heldout"] {
            let rmse = fit[part]["rmse"].as_f64().unwrap();
            assert!(rmse < 20.0, "{part} RMSE {rmse}: {}", r.1);
        }
    }
}

#[test]
fn timing_and_constant_channels_are_named_not_scored_silently() {
    let d = scratch("timing");
    // Whole milliseconds as the time column.
    let ms = recording(&d, "ms.csv", |i, _, b, y| Some(format!("{i},{b:.6},{y:.5}")));
    let ms = ms.to_str().unwrap();
    let r = hil_sim(&["fit", ms, "--model", "algebraic"]);
    refused(&r, &["ms.csv", "time column `t`", "milliseconds"]);
    assert_eq!(r.2.matches("milliseconds").count(), 1, "said twice: {}", r.2);
    let save = d.join("saved");
    let rec = plain(&d);
    let r = hil_sim(&["fit", rec.to_str().unwrap(), "--model", "algebraic", "--save", save.to_str().unwrap()]);
    assert_eq!(r.0, 0, "{}", r.2);
    let params = save.join("algebraic.json");
    let r = hil_sim(&["replay", ms, "--params", params.to_str().unwrap()]);
    refused(&r, &["ms.csv", "milliseconds"]);
    // A constant input: nothing to identify.
    let cin = recording(&d, "cin.csv", |_, t, _, y| Some(format!("{t:.4},0.3,{y:.5}")));
    let r = hil_sim(&["fit", cin.to_str().unwrap(), "--model", "algebraic"]);
    refused(&r, &["cin.csv", "input `b` is constant"]);
    // A constant output: R² undefined, said so, never NaN.
    let cout = recording(&d, "cout.csv", |_, t, b, _| Some(format!("{t:.4},{b:.6},5.0")));
    let r = hil_sim(&["fit", cout.to_str().unwrap(), "--model", "algebraic"]);
    assert_eq!(r.0, 0, "{}", r.2);
    assert!(r.2.contains("output `torque` is constant"), "{}", r.2);
    assert!(r.1.contains("undefined") && !r.1.contains("NaN"), "{}", r.1);
    let r = hil_sim(&["replay", cout.to_str().unwrap(), "--params", params.to_str().unwrap()]);
    assert!(r.2.contains("output `torque` is constant"), "{}", r.2);
    assert!(r.1.contains("R² undefined") && !r.1.contains("NaN"), "{}", r.1);
}

#[test]
fn a_jittered_sampling_clock_is_warned_about_and_rounded_stamps_are_not() {
    let d = scratch("jitter");
    // ±40 % jitter on every interval (a deterministic pseudo-random sequence).
    let mut seed = 12345u64;
    let mut t = 0.0;
    let jit = recording(&d, "jit.csv", |_, _, b, y| {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let u = (seed >> 11) as f64 / (1u64 << 53) as f64;
        t += 1e-3 * (1.0 + 0.8 * (u - 0.5));
        Some(format!("{t:.6},{b:.6},{y:.5}"))
    });
    let r = hil_sim(&["fit", jit.to_str().unwrap(), "--model", "algebraic"]);
    assert_eq!(r.0, 0, "{}", r.2);
    assert!(r.2.contains("non-uniform sampling"), "{}", r.2);
    // Stamps rounded to 0.1 ms at 3 kHz (as in the Dyke files): on their grid, no warning.
    let rounded = recording(&d, "rounded.csv", |i, _, b, y| Some(format!("{:.4},{b:.6},{y:.5}", i as f64 / 3000.0)));
    let r = hil_sim(&["fit", rounded.to_str().unwrap(), "--model", "algebraic"]);
    assert_eq!(r.0, 0, "{}", r.2);
    assert!(!r.2.contains("non-uniform"), "{}", r.2);
}
