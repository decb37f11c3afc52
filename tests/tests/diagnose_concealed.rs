//! Issue 6 acceptance: `diagnose` run blind on recordings with one concealed effect of the
//! missing-physics catalog (`hil-sim simulate --effect`), and on recordings with none.
//!
//! The suite is fixed in advance: every effect a clutch recording with these base models
//! can show, on three base models and excitations (Bouc–Wen under a multi-sine, the
//! algebraic model and the Dahl model under band-limited noise), plus one null recording
//! on each of these and of LuGre under a multi-sine and the tanh model under a triangle,
//! all 30 s at 2 kHz, 4 % of the torque span. The diagnosis is told the
//! base model the user fits (the truth's model) and nothing about the effect; the label
//! stays in the generator. `sensor_offset` is not in the suite: these base models absorb
//! an offset of their input almost entirely (see docs/diagnose.md).
//!
//! [`concealed_effects_are_named_and_null_recordings_give_nothing`] prints the table that
//! docs/diagnose.md carries (and writes it to `target/concealed_suite.md`), then asserts
//! the right top finding on every effect case and no finding on every null case.
//! [`hard_bases_characterised`] (ignored: run it with `--ignored`) does the same on the two
//! pairs where the diagnosis is known to misname some effects (LuGre under a multi-sine,
//! the tanh model under a triangle) and only prints its table (`target/concealed_hard.md`):
//! those misses are documented, not hidden.

use std::path::Path;

use hil_sim::ident::dataset::prepare_recording;
use hil_sim::ident::diagnose::{diagnose, DiagnoseOptions};
use hil_sim::io::recording::Channels;
use hil_sim::progress::NoProgress;
use hil_sim::sim::concealed::{generate, ConcealedSpec};

const EFFECTS: [&str; 9] = [
    "field_lag",
    "transport_delay",
    "saturation",
    "rate_dependence",
    "asymmetry",
    "thermal_drift",
    "slip_speed",
    "inertia",
    "aux_dependence",
];

struct Outcome {
    effect: String,
    base: String,
    excitation: String,
    found: Vec<String>,
    top_params: String,
    truth: String,
    before: f64,
    after: f64,
    seconds: f64,
}

fn run(effect: &str, base: &str, excitation: &str, seed: u64) -> Outcome {
    let spec = ConcealedSpec {
        effect: effect.into(),
        base: base.into(),
        excitation: excitation.into(),
        seed,
        ..ConcealedSpec::default()
    };
    let g = generate(&spec).unwrap_or_else(|e| panic!("{effect}/{base}/{excitation}: {e}"));
    let ch = Channels::default();
    // As `hil-sim diagnose` does: samples the quality check flags (a clipped torque, a
    // standstill) are left out of the fit and the scores.
    let prepared = prepare_recording(g.recording, &ch, 0.7, false).expect("dataset");
    let (rec, data) = (&prepared.recording, &prepared.data);
    let aux = rec.auxiliary_channels(&ch);
    let opts = DiagnoseOptions { model: Some(base.into()), ..DiagnoseOptions::default() };
    let d = diagnose(data, aux, None, ("b", "torque"), &opts, &NoProgress)
        .unwrap_or_else(|e| panic!("{effect}/{base}/{excitation}: {e}"));
    let top = d.findings.first();
    Outcome {
        effect: effect.into(),
        base: base.into(),
        excitation: excitation.into(),
        found: d.findings.iter().map(|f| f.effect.clone()).collect(),
        top_params: top
            .map(|f| {
                f.params
                    .iter()
                    .filter(|(k, _)| ["tau_s", "delay_s", "b_sat"].contains(&k.as_str()))
                    .map(|(k, v)| format!("{k} {v:.4}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            })
            .unwrap_or_default(),
        truth: g
            .label
            .params
            .iter()
            .filter(|(k, _)| k.ends_with("_s") || k.ends_with("_t"))
            .map(|(k, v)| format!("{k} {v:.4}"))
            .collect::<Vec<_>>()
            .join(", "),
        before: top.map_or(d.base_heldout.r_rmse, |f| f.heldout_before.r_rmse),
        after: top.map_or(d.base_heldout.r_rmse, |f| f.heldout_after.r_rmse),
        seconds: d.seconds,
    }
}

/// Runs every effect on each `(base, excitation, seed)` pair of `pairs`, and a null case on
/// each pair of `pairs` and `nulls`; the table and the cases whose outcome was wrong
/// (`effect on base/excitation: findings`).
fn suite(pairs: &[(&str, &str, u64)], nulls: &[(&str, &str, u64)], file: &str) -> (String, Vec<String>) {
    let mut cases: Vec<(&str, &str, &str, u64)> = Vec::new();
    for &(base, exc, seed) in pairs {
        for e in EFFECTS {
            cases.push((e, base, exc, seed));
        }
    }
    for &(base, exc, seed) in pairs.iter().chain(nulls) {
        cases.push(("none", base, exc, seed + 100));
    }
    let outcomes: Vec<Outcome> = cases.iter().map(|&(e, b, x, s)| run(e, b, x, s)).collect();
    let mut table = String::from(
        "| effect | base / excitation | top finding | all findings | verdict | fitted (truth) | held-out R-RMSE before → after | s |\n\
         | --- | --- | --- | --- | --- | --- | --- | --- |\n",
    );
    let mut bad = Vec::new();
    for o in &outcomes {
        let top = o.found.first().map_or("—", String::as_str);
        let verdict = match (o.effect.as_str(), top) {
            ("none", "—") => "no finding (right)",
            ("none", _) => "false alarm",
            (e, t) if e == t => "found",
            _ => "missed",
        };
        if !(verdict == "found" || verdict == "no finding (right)") {
            bad.push(format!("{} on {}/{}: {:?}", o.effect, o.base, o.excitation, o.found));
        }
        table += &format!(
            "| `{}` | {} / {} | {} | {} | {} | {}{} | {:.2} % → {:.2} % | {:.1} |\n",
            o.effect,
            o.base,
            o.excitation,
            top,
            o.found.join(", "),
            verdict,
            o.top_params,
            if o.truth.is_empty() { String::new() } else { format!(" ({})", o.truth) },
            100.0 * o.before,
            100.0 * o.after,
            o.seconds
        );
    }
    println!("{table}");
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../target");
    let _ = std::fs::create_dir_all(&dir);
    let _ = std::fs::write(dir.join(file), &table);
    (table, bad)
}

#[test]
fn concealed_effects_are_named_and_null_recordings_give_nothing() {
    let (table, bad) = suite(
        &[("bouc_wen", "multisine", 21), ("algebraic", "noise", 22), ("dahl", "noise", 25)],
        &[("lugre", "multisine", 24), ("tanh", "triangle", 26)],
        "concealed_suite.md",
    );
    assert!(bad.is_empty(), "{} cases wrong:\n{}\n\n{table}", bad.len(), bad.join("\n"));
}

/// LuGre under a multi-sine and the tanh model under a triangle: characterised, not
/// asserted (docs/diagnose.md lists their misses).
#[test]
#[ignore = "characterisation of the known-weak pairs (≈ 2 min); run with --ignored"]
fn hard_bases_characterised() {
    let (_, bad) = suite(&[("lugre", "multisine", 24), ("tanh", "triangle", 26)], &[], "concealed_hard.md");
    println!("{} cases wrong:\n{}", bad.len(), bad.join("\n"));
}
