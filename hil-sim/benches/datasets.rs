//! Speed of fitting on lab-sized data (issue 16, acceptance 4), measured once each (a fit of
//! every model takes seconds; criterion's ten samples would take many minutes):
//!
//! - every model on a 60,000-sample recording (the first 60,000 samples of `ranran_50.csv`,
//!   `--input D --output F --command Y`, `--train 0.85`);
//! - Spencer's model (and the closed-form algebraic one) on a 5-run dataset of 60,000 samples
//!   each (windows of `ranran_50.csv` and `ransim_u.csv`; the state restarts at every run).
//!
//! `cargo bench -p hil-sim --bench datasets`. Prints the wall times; no assertion (speed is
//! reported, never asserted).

use std::time::Instant;

use hil_sim::ident::dataset::{prepare_recording, Prepared};
use hil_sim::ident::fit::{fit, FitOptions};
use hil_sim::ident::runs::join_prepared;
use hil_sim::io::manifest::Role;
use hil_sim::io::recording::{Channels, Column, Recording};

const N: usize = 60_000;

fn channels() -> Channels {
    Channels { time: "t".into(), input: "D".into(), output: "F".into(), command: Some("Y".into()), set: Vec::new() }
}

/// Samples `from..from + N` of a bundled Dyke file, prepared as `fit` does.
fn window(file: &str, from: usize) -> Prepared {
    let path = hil_sim::io::bundled::data_file(file).expect("bundled data");
    let rec = Recording::read(&path).expect("readable");
    let cols: Vec<Column> = rec
        .columns
        .iter()
        .map(|c| Column { name: c.name.clone(), values: c.values[from..from + N].to_vec() })
        .collect();
    let name = path.with_file_name(format!("{file}@{from}").replace('/', "_"));
    prepare_recording(Recording::from_columns(&name, cols, vec![]), &channels(), 0.85, false).expect("dataset")
}

fn main() {
    let one = window("dyke/ranran_50.csv", 0);
    let opts = FitOptions::default();
    let t0 = Instant::now();
    let mut each = Vec::new();
    for m in model_core::MODELS.iter() {
        let t = Instant::now();
        let r = fit(m.id, &one.data, &opts).expect("fit");
        each.push(format!("{} {:.2} s (held-out R² {:.3})", m.id, t.elapsed().as_secs_f64(), r.heldout.r2));
    }
    println!("every model on {N} samples: {:.1} s", t0.elapsed().as_secs_f64());
    for e in each {
        println!("  {e}");
    }
    let runs = vec![
        (window("dyke/ranran_50.csv", 0), Role::Train),
        (window("dyke/ranran_50.csv", 14_000), Role::Train),
        (window("dyke/ransim_u.csv", 0), Role::Train),
        (window("dyke/ranran_50.csv", 7_000), Role::Validate),
        (window("dyke/ransim_u.csv", 96), Role::Validate),
    ];
    let set = join_prepared(runs).expect("joined");
    for id in ["algebraic", "spencer"] {
        let t = Instant::now();
        let r = fit(id, &set.joined.data, &opts).expect("fit");
        println!(
            "{id} on 5 runs × {N} samples: {:.1} s (pooled held-out R² {:.3})",
            t.elapsed().as_secs_f64(),
            r.heldout.r2
        );
    }
}
