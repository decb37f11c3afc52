//! Speed of identification and replay on the real Dyke recording (issue 3, point 2).
//!
//! `cargo bench -p hil-sim --bench fit`. Figures to compare with the SciPy baseline in
//! `scripts/scipy-baseline/` (same model, data and split).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use hil_sim::ident::fit::{fit, Dataset, DelayChoice, FitOptions};
use hil_sim::io::recording::Channels;
use hil_sim::io::recording::Recording;
use hil_sim::models::{replay, RateSpec};
use model_core::Sample;

fn dyke(train: f64, take: Option<usize>) -> Dataset {
    let path = hil_sim::io::bundled::data_file("dyke/ranran_50.csv").expect("bundled data");
    let mut rec = Recording::read(&path).expect("readable");
    if let Some(n) = take {
        for c in &mut rec.columns {
            c.values.truncate(n);
        }
        rec.lines.truncate(n);
    }
    let ch = Channels {
        time: "t".into(),
        input: "D".into(),
        output: "F".into(),
        command: Some("Y".into()),
        set: Vec::new(),
    };
    Dataset::new(&rec, &ch, train, None).expect("dataset")
}

fn bench(c: &mut Criterion) {
    // Algebraic model, closed-form least squares on exactly 60,000 training samples.
    let d60 = dyke(60_000.0 / 74_068.0, None);
    assert_eq!(d60.train_end, 60_000);
    let mut g = c.benchmark_group("fit");
    g.sample_size(20);
    // The closed-form fit itself (channels as recorded), then with the input delay fitted
    // too (`--delay auto`, the CLI default: one closed-form fit per delay on a grid).
    let off = FitOptions { delay: DelayChoice::Off, ..FitOptions::default() };
    g.bench_function("algebraic_60k", |b| b.iter(|| fit("algebraic", &d60, &off).expect("fit")));
    g.bench_function("algebraic_60k_delay_auto", |b| {
        b.iter(|| fit("algebraic", &d60, &FitOptions::default()).expect("fit"))
    });
    let d = dyke(0.85, None);
    g.sample_size(10);
    g.bench_function("spencer_ranran50_train0.85", |b| {
        b.iter(|| fit("spencer", &d, &FitOptions::default()).expect("fit"))
    });
    g.finish();

    // Replay throughput of the f32 core (Estimator path), one core.
    let samples: Vec<Sample> = d.samples();
    let mut g = c.benchmark_group("replay");
    g.throughput(Throughput::Elements(samples.len() as u64));
    for (id, p) in [
        ("algebraic", vec![100.0f32, 20.0, 1.0, -100.0]),
        ("bouc_wen", vec![500.0, 10.0, 10.0, 1.0, 2.0, 20.0, 5.0, 0.0]),
        // Spencer et al. (1997) for this damper; the command channel Y drives it.
        ("spencer", vec![21.0, 3.5, 46.9, 283.0, 2.95, 5.0, 14.3, 140.0, 695.0, 363.0, 363.0, 301.0, 2.0, 190.0]),
    ] {
        g.bench_function(id, |b| b.iter(|| replay(id, &p, d.dt as f32, RateSpec::Backward, &samples).expect("replay")));
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
