//! Stage 3 of a diagnosis, naming: where on its grid each candidate's refit starts. An
//! input transform's grid is profiled ([`super::profile`]); any other candidate's is
//! scanned with the base model's Jacobian standing in for the refit of θ
//! ([`Problem::scan_cost`]), one run of the base model per grid value.

use super::augment::{Fitted, Problem};
use super::candidates::Candidate;
use super::refit::Start;

/// Starting values for the candidate's refit: its grid value with the lowest linearised
/// training cost (refined by a parabola through its neighbours on the grid) and, when the
/// cost has another local minimum on the grid, the best of those (a base model can absorb
/// part of an effect, which shifts the linearised minimum; the refit decides).
pub fn starts_on_grid(prob: &Problem<'_>, c: &Candidate, current: &Fitted, jac: &[Vec<f64>]) -> Vec<Start> {
    let cost_at = |g: f64| -> Option<f64> {
        let (transforms, terms) = c.on_top(current, g);
        prob.scan_cost(&transforms, &terms, &current.theta, jac)
    };
    if c.grid.len() < 2 {
        return c.grid.iter().map(|&g| (g, None)).collect();
    }
    if c.grid.first().is_some_and(|&g| (c.build)(g).transform.is_some()) {
        return super::profile::starts(prob, c, current);
    }
    let costs: Vec<f64> = c.grid.iter().map(|&g| cost_at(g).unwrap_or(f64::INFINITY)).collect();
    let finite = |k: &usize| costs[*k].is_finite();
    let Some(k) = (0..costs.len()).filter(finite).min_by(|&a, &b| costs[a].total_cmp(&costs[b])) else {
        return Vec::new();
    };
    let mut best = (c.grid[k], costs[k]);
    if k > 0 && k + 1 < costs.len() {
        let (l, m, r) = (costs[k - 1], costs[k], costs[k + 1]);
        let curv = l - 2.0 * m + r;
        if curv > 0.0 && curv.is_finite() {
            let off = (0.5 * (l - r) / curv).clamp(-0.5, 0.5);
            let g = if off >= 0.0 {
                c.grid[k] + off * (c.grid[k + 1] - c.grid[k])
            } else {
                c.grid[k] - off * (c.grid[k - 1] - c.grid[k])
            };
            if let Some(cost) = cost_at(g).filter(|v| *v < best.1) {
                best = (g, cost);
            }
        }
    }
    let mut out = vec![(best.0, None)];
    let local_min = |j: usize| {
        let l = if j > 0 { costs[j - 1] } else { f64::INFINITY };
        let r = costs.get(j + 1).copied().unwrap_or(f64::INFINITY);
        costs[j] <= l && costs[j] <= r
    };
    if let Some(j) = (0..costs.len())
        .filter(finite)
        .filter(|&j| j.abs_diff(k) > 1 && local_min(j))
        .min_by(|&a, &b| costs[a].total_cmp(&costs[b]))
    {
        out.push((c.grid[j], None));
    }
    out
}
