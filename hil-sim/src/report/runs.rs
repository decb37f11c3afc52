//! The per-run section of a dataset's fit report (issue 16): one table with each model's
//! metrics on each run, beside the pooled ones of the results table.

use super::Report;
use crate::ident::dataset::Dataset;
use crate::ident::fit::FitResult;

/// Add the section (nothing for a single recording).
pub fn section(rep: &mut Report, data: &Dataset, results: &[FitResult]) {
    if data.runs.is_empty() {
        return;
    }
    rep.heading("Each run");
    rep.paragraph(&format!(
        "{} runs identified as one: the model's state restarts at each run, the parameters are shared. Each run \
         is scored on its held-out samples (a `validate` run whole), or on its training samples when it has none.",
        data.runs.len()
    ));
    let rows: Vec<Vec<String>> = results
        .iter()
        .flat_map(|r| {
            r.runs.iter().map(move |run| {
                let file = std::path::Path::new(&run.file);
                vec![
                    r.model.clone(),
                    file.file_name().map_or(run.file.clone(), |f| f.to_string_lossy().into_owned()),
                    run.role.label().to_owned(),
                    run.part.to_owned(),
                    format!("{:.4}", run.metrics.rmse),
                    format!("{:.4}", run.metrics.r2),
                    format!("{:.2} %", 100.0 * run.metrics.r_rmse),
                ]
            })
        })
        .collect();
    rep.table(&["model", "run", "role", "scored", "RMSE", "R²", "R-RMSE"], &rows);
}
