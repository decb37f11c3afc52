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

/// Write a fit report: the table, the error bars, and the plots of the best model (by
/// held-out RMSE). Returns the path of `index.html`.
pub fn write(
    dir: &std::path::Path,
    title: &str,
    data: &Dataset,
    results: &[FitResult],
    labels: &Labels,
) -> Result<PathBuf, FitPageError> {
    let mut rep = Report::new(title);
    rep.paragraph(&format!(
        "{} samples at {:.1} Hz; fitted on the first {} samples, scored on the last {}. Metrics are from the \
         f32 replay through model-core (the firmware's code), one step per sample.",
        data.len(),
        1.0 / data.dt,
        data.train_end,
        data.len() - data.train_end
    ));
    results_table(&mut rep, results);
    super::runs::section(&mut rep, data, results);
    let stem = |m: &str| format!("fit_{m}");
    error_bars(&mut rep, dir, "fit", results)?;
    if let Some(best) = results.iter().min_by(|x, y| x.heldout.rmse.total_cmp(&y.heldout.rmse)) {
        rep.heading(&format!("Best held-out model: {}", best.model));
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
