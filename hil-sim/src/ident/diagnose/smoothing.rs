//! What the models are fed: the recorded input smoothed zero-phase at fs/8, run by run, and
//! its rate at the input's content cutoff (`numerics::derivative`).

use super::options::DiagnoseOptions;
use crate::ident::fit::Dataset;

/// `data` with the models' input smoothed zero-phase at [`CUTOFF_OF_FS`] of the sampling
/// rate, run by run, and its rate at [`content_cutoff`] (the raw input's rate when that is
/// fs/8, [`rates_of_smoothed`]; unless `opts` chose an estimator),
/// that cutoff (Hz), and the note saying so when it is below fs/8 (`input`: the input
/// channel's name). The input itself is smoothed, not only its rate: the hysteresis models'
/// state moves with every increment of the input, and a reading's noise adds increments back
/// and forth that wear the loop down faster than the clutch's; a lag of the input, which
/// smooths too, then appeared to explain the reading's noise (Dahl nulls named `field_lag`
/// on LuGre). The input is smoothed at fs/8, not at the content cutoff: a delay of an input
/// smoothed that low is itself a lag, and a two-pole lag was then named a delay.
///
/// [`CUTOFF_OF_FS`]: crate::numerics::derivative::CUTOFF_OF_FS
/// [`content_cutoff`]: crate::numerics::derivative::content_cutoff
/// [`rates_of_smoothed`]: crate::numerics::derivative::rates_of_smoothed
pub(super) fn models_input(data: &Dataset, opts: &DiagnoseOptions, input: &str) -> (Dataset, f64, Option<String>) {
    use crate::numerics::derivative::{
        content_cutoff, rates_of_smoothed, smooth_below, CUTOFF_OF_CONTENT, CUTOFF_OF_FS,
    };
    let mut data = data.clone();
    let top = CUTOFF_OF_FS / data.dt;
    if opts.rate.is_some() {
        // The models use the chosen estimator: no given rates, so the cutoff is never read.
        return (data, top, None);
    }
    let cutoff = content_cutoff(&data.input, data.dt);
    for run in data.spans() {
        let smooth = smooth_below(&data.input[run.start..run.end], data.dt, top);
        data.input[run.start..run.end].copy_from_slice(&smooth);
    }
    data.rates = Some(rates_of_smoothed(&data.input, data.dt, cutoff));
    let note = (cutoff < top).then(|| {
        format!(
            "the models' rate of {input} was smoothed (zero phase) at {cutoff:.0} Hz, not {top:.0} Hz: 99.9 % of \
             {input}'s power lies below {:.1} Hz, and the band above it only adds the reading's noise to the rate",
            cutoff / CUTOFF_OF_CONTENT
        )
    });
    (data, cutoff, note)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_models_input_is_smoothed_run_by_run() {
        // Two runs joined with a 0.4 T jump: the smoothing restarts at the join, so the
        // second run's first samples carry nothing of the first run's level.
        let (dt, n) = (1e-3, 2_000);
        let mut data = super::super::tests::recording(None, 3);
        data.input = (0..2 * n).map(|i| if i < n { 0.1 } else { 0.5 } + 0.01 * (i as f64 * dt * 40.0).sin()).collect();
        data.output = vec![0.0; 2 * n];
        data.time = (0..2 * n).map(|i| i as f64 * dt).collect();
        data.dt = dt;
        data.excluded = vec![false; 2 * n];
        data.runs = (0..2)
            .map(|r| crate::ident::dataset::RunSpan {
                file: std::path::PathBuf::from(format!("run{r}.csv")),
                role: Default::default(),
                start: r * n,
                train_end: r * n + n * 3 / 4,
                end: (r + 1) * n,
            })
            .collect();
        let (smoothed, _, _) = models_input(&data, &DiagnoseOptions::default(), "b");
        for i in [n - 1, n, n + 1] {
            assert!(
                (smoothed.input[i] - data.input[i]).abs() < 2e-3,
                "sample {i}: {} for {}",
                smoothed.input[i],
                data.input[i]
            );
        }
        // …and smooths: the sine's 40 rad/s is kept, a sample-to-sample alternation is not.
        let mut noisy = data.clone();
        noisy.input.iter_mut().enumerate().for_each(|(i, v)| *v += if i % 2 == 0 { 1e-3 } else { -1e-3 });
        let (quiet, _, _) = models_input(&noisy, &DiagnoseOptions::default(), "b");
        let left = (100..n - 100).map(|i| (quiet.input[i] - smoothed.input[i]).abs()).fold(0.0, f64::max);
        assert!(left < 2.5e-4, "{left} T of a ±1 mT alternation left");
    }
}
