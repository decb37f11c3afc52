//! Speed of fitting on lab-sized data (issue 16, acceptance 4), measured once each (a fit of
//! every model takes seconds; criterion's ten samples would take many minutes):
//!
//! - every model on a 60,000-sample recording (the first 60,000 samples of `ranran_50.csv`,
//!   `--input D --output F --command Y`, `--train 0.85`), fitted side by side as `fit --model
//!   all` does; then the same on a simulated one (`hil-sim simulate --effect none`: Bouc–Wen
//!   clutch, multisine, 30 s at 2 kHz);
//! - Spencer's model (and the closed-form algebraic one) on a 5-run dataset of 60,000 samples
//!   each (windows of `ranran_50.csv` and `ransim_u.csv`; the state restarts at every run).
//!
//! `cargo bench -p hil-sim --bench datasets`. Prints the wall times and the process's CPU time
//! (on a shared machine the wall time says more about the neighbours; on an idle 2-core one it is
//! about half the CPU time, the longest fits being started first); no assertion (speed is
//! reported, never asserted).

use std::time::Instant;

use hil_sim::ident::dataset::{prepare_recording, Prepared};
use hil_sim::ident::fit::job::fit_many;
use hil_sim::ident::fit::{fit, Dataset, FitOptions};
use hil_sim::ident::runs::join_prepared;
use hil_sim::io::manifest::Role;
use hil_sim::io::recording::{Channels, Column, Recording};
use hil_sim::progress::NoProgress;
use hil_sim::sim::concealed::{generate, ConcealedSpec};

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

/// CPU time of this process so far (user + system, every thread), seconds.
fn cpu_seconds() -> f64 {
    // SAFETY: getrusage writes the struct it is given and nothing else.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    if unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) } != 0 {
        return f64::NAN;
    }
    let tv = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    tv(u.ru_utime) + tv(u.ru_stime)
}

/// Every model on `data`, side by side (as `fit --model all`); prints wall and CPU time and
/// each model's fit seconds (wall, while sharing the cores with the others).
fn every_model(what: &str, data: &Dataset) {
    let ids: Vec<String> = model_core::MODELS.iter().map(|m| m.id.to_owned()).collect();
    let (t0, c0) = (Instant::now(), cpu_seconds());
    let results = fit_many(data, &ids, &FitOptions::default(), &NoProgress).expect("fit");
    let (wall, cpu) = (t0.elapsed().as_secs_f64(), cpu_seconds() - c0);
    println!(
        "every model on {what} ({} samples, {} threads): {wall:.1} s wall, {cpu:.1} s CPU \
         (issue 16: under 10 s wall on 2 cores; CPU / 2 = {:.1} s)",
        data.len(),
        rayon::current_num_threads(),
        cpu / 2.0
    );
    for r in results {
        println!("  {} {:.2} s (held-out R² {:.3})", r.model, r.fit_seconds, r.heldout.r2);
    }
}

fn main() {
    let one = window("dyke/ranran_50.csv", 0);
    every_model("ranran_50.csv[0..60000]", &one.data);
    let spec = ConcealedSpec { effect: "none".into(), base: "bouc_wen".into(), ..ConcealedSpec::default() };
    let sim = generate(&spec).expect("simulated recording").recording;
    let sim = prepare_recording(sim, &Channels::default(), 0.85, false).expect("dataset");
    every_model("a simulated clutch", &sim.data);
    let opts = FitOptions::default();
    let runs = vec![
        (window("dyke/ranran_50.csv", 0), Role::Train),
        (window("dyke/ranran_50.csv", 14_000), Role::Train),
        (window("dyke/ransim_u.csv", 0), Role::Train),
        (window("dyke/ranran_50.csv", 7_000), Role::Validate),
        (window("dyke/ransim_u.csv", 96), Role::Validate),
    ];
    let set = join_prepared(runs).expect("joined");
    for id in ["algebraic", "spencer"] {
        let (t, c) = (Instant::now(), cpu_seconds());
        let r = fit(id, &set.joined.data, &opts).expect("fit");
        println!(
            "{id} on 5 runs × {N} samples: {:.1} s wall, {:.1} s CPU (pooled held-out R² {:.3})",
            t.elapsed().as_secs_f64(),
            cpu_seconds() - c,
            r.heldout.r2
        );
    }
}
