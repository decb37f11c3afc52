//! Speed of `diagnose` (issue 6, point 3: a 30 s recording at 2 kHz in ≤ 10 s).
//!
//! `cargo bench -p hil-sim --bench diagnose`. The recording is `hil-sim simulate --effect
//! field_lag --base bouc_wen --excitation multisine` (30 s, 2 kHz, 60,000 samples), diagnosed
//! with its base model given (`--model bouc_wen`) and chosen (`--model auto`, ten seed
//! models fitted first), as the CLI runs it (both cores).

use criterion::{criterion_group, criterion_main, Criterion};
use hil_sim::ident::diagnose::{diagnose, DiagnoseOptions};
use hil_sim::ident::fit::Dataset;
use hil_sim::io::recording::Channels;
use hil_sim::progress::NoProgress;
use hil_sim::sim::concealed::{generate, ConcealedSpec};

fn bench(c: &mut Criterion) {
    let spec = ConcealedSpec { effect: "field_lag".into(), base: "bouc_wen".into(), ..ConcealedSpec::default() };
    let g = generate(&spec).expect("concealed recording");
    let rec = g.recording;
    let ch = Channels::default();
    let data = Dataset::new(&rec, &ch, 0.7, None).expect("dataset");
    assert_eq!(data.len(), 60_000);
    let aux = rec.auxiliary_channels(&ch);
    let mut group = c.benchmark_group("diagnose");
    group.sample_size(10);
    for (name, model) in [("bouc_wen_30s_2khz", Some("bouc_wen")), ("auto_30s_2khz", None)] {
        let opts = DiagnoseOptions { model: model.map(str::to_owned), ..DiagnoseOptions::default() };
        group.bench_function(name, |b| {
            b.iter(|| diagnose(&data, aux.clone(), None, ("b", "torque"), &opts, &NoProgress).expect("diagnosis"))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
