//! A candidate refitted on top of the current model: θ, β and the candidate's value
//! jointly ([`Problem::refit`]) from each of its starting points, the best by training
//! error kept.

use super::augment::{Fitted, Problem, Tune};
use super::candidates::Candidate;

/// A starting value of a candidate's refit, with the base parameters θ to start from
/// (`None`: the current model's).
pub type Start = (f64, Option<Vec<f64>>);

/// Refit candidate `c` on top of `current` from each of `starts` (its value); the best by
/// training error, with its value.
pub fn refit_candidate(
    prob: &Problem<'_>,
    c: &Candidate,
    current: &Fitted,
    starts: &[Start],
    iterations: usize,
) -> Option<(Fitted, f64)> {
    let build = |g: f64| {
        let p = (c.build)(g);
        (p.transform, p.terms)
    };
    let (lo, hi) = c.bounds();
    starts
        .iter()
        .filter_map(|(g, theta)| {
            let g = *g;
            let theta = theta.as_deref().unwrap_or(&current.theta);
            if c.grid.len() > 1 {
                let tune = Tune { build: &build, start: g, lo, hi, log: lo > 0.0 };
                prob.refit(&current.transforms, &current.terms, Some(&tune), theta, iterations)
            } else {
                let (transforms, terms) = c.on_top(current, g);
                prob.refit(&transforms, &terms, None, theta, iterations).map(|r| (r.0, g))
            }
        })
        .min_by(|a, b| a.0.train_mse.total_cmp(&b.0.train_mse))
}
