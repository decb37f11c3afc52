//! Starting values of an input transform (a lag, a delay, a saturation, an offset) from a
//! profile of its grid: a transform of the input moves the base model's optimum far (its
//! rate term absorbs part of a delay or a lag), so the linearised scan ([`super::scan`])
//! cannot follow. The cost at a subset of the grid comes from a short refit of θ instead,
//! walked outward from the identity so that each refit starts from its neighbour's θ (a
//! continuation: a refit from the untransformed θ does not converge for a large delay, and
//! its cost would rank a small one first).

use rayon::prelude::*;

use super::augment::{Fitted, Problem};
use super::candidates::Candidate;
use super::refit::Start;

/// Grid points of an input transform's profiled scan on each side of the identity, and the
/// iterations of each refit.
const PROFILE_POINTS: usize = 8;
const PROFILE_ITERATIONS: usize = 3;
/// Grid values between two starts for them to count as different basins.
const PROFILE_GAP: usize = 2;
/// Samples (from the start) whose training rows rank an input transform's grid values.
const PROFILE_SAMPLES: usize = 12_000;

/// The best value of the profile and the best one in another basin (not next to it on the
/// grid), each with the θ its profile refit reached.
pub fn starts(prob: &Problem<'_>, c: &Candidate, current: &Fitted) -> Vec<Start> {
    // The first PROFILE_SAMPLES of the training part rank the grid values.
    let short = prob.on_rows(prob.train.iter().copied().take_while(|&i| i < PROFILE_SAMPLES).collect());
    let prob = if short.train.len() >= 1000 { &short } else { prob };
    let profile: Vec<(f64, f64, Option<Vec<f64>>)> = continuation_chains(c, &prob.data.input, prob.data.dt)
        .par_iter()
        .flat_map_iter(|chain| {
            let mut theta = current.theta.clone();
            let mut out = Vec::with_capacity(chain.len());
            for &g in chain {
                let (transforms, terms) = c.on_top(current, g);
                match prob.refit_train(&transforms, &terms, &theta, PROFILE_ITERATIONS) {
                    Some((refitted, mse)) => {
                        out.push((g, mse, Some(refitted.clone())));
                        theta = refitted;
                    }
                    None => out.push((g, f64::INFINITY, None)),
                }
            }
            out
        })
        .collect();
    let mut order: Vec<usize> = (0..profile.len()).filter(|&k| profile[k].1.is_finite()).collect();
    order.sort_by(|&a, &b| profile[a].1.total_cmp(&profile[b].1));
    // The best value, and the best one that is not next to it on the grid (another basin).
    let gap = |a: f64, b: f64| c.grid.iter().filter(|&&g| (g - a) * (g - b) < 0.0).count() > PROFILE_GAP;
    let mut out: Vec<Start> = Vec::new();
    if let Some(&a) = order.first() {
        out.push((profile[a].0, profile[a].2.clone()));
        if let Some(&b) = order.iter().find(|&&j| gap(profile[a].0, profile[j].0)) {
            out.push((profile[b].0, profile[b].2.clone()));
        }
    }
    out
}

/// The grid of an input-transform candidate as chains walked outward from the identity:
/// values split by sign (a delay or an offset either way; a lag or a saturation level has
/// one sign) and each side ordered by how far the transform moves the input, thinned to
/// [`PROFILE_POINTS`].
fn continuation_chains(c: &Candidate, x: &[f64], dt: f64) -> Vec<Vec<f64>> {
    let distance = |g: f64| -> f64 {
        let Some(t) = (c.build)(g).transform else { return f64::INFINITY };
        let y = t.apply(x, dt);
        x.iter().zip(&y).map(|(a, b)| (a - b) * (a - b)).sum::<f64>()
    };
    [false, true]
        .iter()
        .filter_map(|&negative| {
            let mut side: Vec<(f64, f64)> =
                c.grid.iter().filter(|&&g| (g < 0.0) == negative).map(|&g| (distance(g), g)).collect();
            side.sort_by(|a, b| a.0.total_cmp(&b.0));
            let step = side.len().div_ceil(PROFILE_POINTS).max(1);
            let chain: Vec<f64> = side.iter().step_by(step).map(|p| p.1).collect();
            (!chain.is_empty()).then_some(chain)
        })
        .collect()
}
