//! A parameter file remembers the channels it was fitted on (issue 18, defect 8): `fit
//! --save` records them, `replay` uses them when no flag names others, and a set fitted with
//! a command channel is not replayed on a recording without one (Spencer's damper fitted with
//! `--command Y` and replayed without it gave 486 N of error instead of 196 N).

mod common;

use hil_sim::io::recording::{Column, Recording};

#[test]
fn replay_uses_the_fitted_channels_and_refuses_a_missing_command() {
    let dir = common::scratch("fitted-channels");
    let dyke = hil_sim::io::bundled::data_file("dyke/ranran_50.csv").unwrap();
    let full = Recording::read(&dyke).unwrap();
    // The first 15,000 samples, with and without the command channel Y.
    let take = |keep_y: bool| {
        let cols: Vec<Column> = full
            .columns
            .iter()
            .filter(|c| keep_y || c.name != "Y")
            .map(|c| Column { name: c.name.clone(), values: c.values[..15_000].to_vec() })
            .collect();
        Recording::from_columns(&dyke, cols, vec![])
    };
    let (with_y, without_y) = (dir.join("with_y.csv"), dir.join("without_y.csv"));
    for (path, keep) in [(&with_y, true), (&without_y, false)] {
        let mut out = Vec::new();
        take(keep).write_csv(&mut out).unwrap();
        std::fs::write(path, out).unwrap();
    }
    let (w, wo, save) = (with_y.to_str().unwrap(), without_y.to_str().unwrap(), dir.join("p"));
    let (code, _, err) = common::hil_sim(&[
        "fit",
        w,
        "--input",
        "D",
        "--output",
        "F",
        "--command",
        "Y",
        "--model",
        "spencer",
        "--save",
        save.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let params = save.join("spencer.json");
    let pf: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&params).unwrap()).unwrap();
    assert_eq!(pf["channels"]["command"], "Y", "{pf}");
    assert_eq!(pf["channels"]["input"], "D", "{pf}");
    let p = params.to_str().unwrap();
    let rmse = |args: &[&str]| {
        let (code, out, err) = common::hil_sim(args);
        assert_eq!(code, 0, "{args:?}: {err}");
        let v: serde_json::Value = serde_json::from_str(&out).unwrap();
        v["metrics"]["rmse"].as_f64().unwrap()
    };
    // No channel flags at all: the file's D, F and Y are used, as when they are named.
    let named = rmse(&["replay", w, "--params", p, "--input", "D", "--output", "F", "--command", "Y", "--json"]);
    let remembered = rmse(&["replay", w, "--params", p, "--json"]);
    assert_eq!(named, remembered);
    // A recording without the command: one line naming the file, the channel and the way out.
    let (code, out, err) = common::hil_sim(&["replay", wo, "--params", p, "--json"]);
    assert_ne!(code, 0);
    assert!(out.is_empty(), "{out}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("without_y.csv") && err.contains("command channel `Y`") && err.contains("--set Y="), "{err}");
}
