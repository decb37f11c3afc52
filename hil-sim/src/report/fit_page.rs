//! The page `fit --out` writes: the results table, the error bars, the best model's plots,
//! the warnings and every model's hysteresis loops.

use std::path::PathBuf;

use thiserror::Error;

use super::fit::{error_bars, fit_plots, loop_plots, results_table, Labels};
use super::plot::PlotError;
use super::{Report, ReportError};
use crate::ident::dataset::Dataset;
use crate::ident::fit::FitResult;

/// Why the fit page was not written.
#[derive(Debug, Error)]
pub enum FitPageError {
    #[error(transparent)]
    Plot(#[from] PlotError),
    #[error(transparent)]
    Report(#[from] ReportError),
}

/// Write a fit report: the quality warnings (already free of the user's folders), the
/// table, the error bars, and the plots of the best model (by held-out RMSE). Returns the
/// path of `index.html`.
pub fn write(
    dir: &std::path::Path,
    title: &str,
    data: &Dataset,
    results: &[FitResult],
    labels: &Labels,
    warnings: &[String],
) -> Result<PathBuf, FitPageError> {
    let mut rep = Report::new(title);
    for w in warnings {
        rep.paragraph(&format!("**Quality warning:** {w}"));
    }
    let fitted = (0..data.len()).filter(|&i| data.is_train(i)).count();
    let split = if data.runs.len() > 1 {
        format!(
            "{} runs, each model's state restarting at each; fitted on {fitted} samples, scored on the other {}",
            data.runs.len(),
            data.len() - fitted
        )
    } else {
        format!("fitted on the first {fitted} samples, scored on the last {}", data.len() - fitted)
    };
    rep.paragraph(&format!(
        "{} samples at {:.1} Hz; {split}. Metrics are from the f32 replay through model-core (the firmware's \
         code), one step per sample.",
        data.len(),
        1.0 / data.dt,
    ));
    results_table(&mut rep, results, labels);
    super::runs::section(&mut rep, data, results);
    let stem = |m: &str| format!("fit_{m}");
    error_bars(&mut rep, dir, "fit", results)?;
    if let Some(best) = results.iter().min_by(|x, y| x.heldout.rmse.total_cmp(&y.heldout.rmse)) {
        rep.heading(&format!("Best held-out model: {}", best.model));
        rep.paragraph(&super::scores::heldout_note(data, best, labels.output_name(), labels.output_unit()));
        fit_plots(&mut rep, dir, &stem(&best.model), data, best, labels)?;
    }
    for r in results.iter().filter(|r| !r.warnings.is_empty()) {
        for w in &r.warnings {
            rep.paragraph(&format!("**Warning ({}):** {w}", r.model));
        }
    }
    rep.heading("Hysteresis loops of every model (held-out part)");
    loop_plots(&mut rep, dir, "heldout", data, results, labels)?;
    Ok(rep.write(dir)?)
}
