//! Per-run metrics of a dataset fit (shared/spec/cli-contract.md "Datasets": `runs` in each
//! fit result): each run scored on its own held-out samples, or its training ones when it
//! has none.

use serde::Serialize;

use super::Dataset;
use crate::numerics::metrics::Metrics;

/// One run's metrics in a dataset fit (`runs` of the contract's fit result).
#[derive(Clone, Debug, Serialize)]
pub struct RunMetrics {
    pub file: String,
    pub role: crate::io::manifest::Role,
    /// Which part of the run `metrics` cover: `heldout` (a validate run, or the end of a run
    /// when no run is marked validate) or `train` (a train run of a dataset with validate runs).
    pub part: &'static str,
    pub metrics: Metrics,
    /// On the run's training samples, when it has both parts.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub train: Option<Metrics>,
}

/// Each run's metrics (none for a single recording): its held-out samples, else its training ones.
pub(super) fn per_run_metrics(
    data: &Dataset,
    train: &[usize],
    heldout: &[usize],
    score: &dyn Fn(&[usize]) -> Metrics,
) -> Vec<RunMetrics> {
    let within = |rows: &[usize], r: &crate::ident::dataset::RunSpan| -> Vec<usize> {
        rows.iter().copied().filter(|i| (r.start..r.end).contains(i)).collect()
    };
    data.runs
        .iter()
        .map(|r| {
            let (tr, ho) = (within(train, r), within(heldout, r));
            let (part, rows) = if ho.is_empty() { ("train", &tr) } else { ("heldout", &ho) };
            RunMetrics {
                file: r.file.display().to_string(),
                role: r.role,
                part,
                metrics: score(rows),
                train: (!ho.is_empty() && !tr.is_empty()).then(|| score(&tr)),
            }
        })
        .collect()
}
