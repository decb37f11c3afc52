//! Parameters the data cannot tell from zero, held there (issue 16): a free parameter whose
//! 95 % confidence interval spans zero ([`confidence`]) is fixed at zero and the others are
//! refitted by Levenberg–Marquardt from the fitted set, on the same training data and
//! delays. The held fit is kept when its training cost (normalised mean square) is at most
//! [`TOLERANCE`] above the free fit's; every such parameter is named in the warning, as held
//! or, when holding it costs more than that (or zero is outside its range), as undetermined.
//!
//! All of them are tried together first; when that costs too much, the least determined one
//! (the widest interval relative to its value) alone.

use super::confidence::{self, Unresolved};
use super::lm;
use super::objective::Objective;
use super::simulate::Simulator;
use crate::models::search::ModelSpec;

/// Relative rise of the training cost a held fit may cost and still be kept (1 %).
pub const TOLERANCE: f64 = 0.01;

/// The outcome of [`resolve`].
#[derive(Clone, Debug, Default)]
pub struct Resolved {
    /// The model's parameters: the held fit's when kept, else the fit's as given.
    pub params: Vec<f64>,
    /// Parameters held at zero, by name.
    pub held: Vec<String>,
    /// The warning naming the undetermined parameters (`None`: all are determined).
    pub warning: Option<String>,
    /// Model runs spent on the checks and refits.
    pub evaluations: usize,
}

/// The data and the fitted set [`resolve`] works on.
pub struct Fitted<'a> {
    pub sim: &'a dyn Simulator,
    /// The search (the model's own parameters first; delay entries, if any, are ignored).
    pub spec: &'a ModelSpec,
    pub kin: &'a [model_core::Kin],
    pub y: &'a [f64],
    pub rows: &'a [usize],
    pub scale: f64,
    /// Fitted delays (input, command), samples.
    pub delays: (f64, f64),
    pub starts: &'a [usize],
    /// The fitted model parameters (no delay entries).
    pub params: &'a [f64],
}

/// Find the parameters of `f` whose interval spans zero and hold what the data allow at
/// zero (`lm_iterations` Jacobians per refit).
pub fn resolve(f: &Fitted<'_>, lm_iterations: usize) -> Resolved {
    let mut shifted = Vec::new();
    crate::models::alignment::shift_kin_runs(f.kin, f.delays.0, f.delays.1, f.starts, &mut shifted);
    let mut spec = f.spec.clone();
    spec.params.truncate(f.sim.n_params());
    let obj = Objective::new(f.sim, &spec, &shifted, f.y, f.rows, f.scale);
    let names: Vec<&'static str> = spec.params.iter().map(|p| p.name).collect();
    let unresolved = confidence::spanning_zero(&obj, f.params);
    let mut out = Resolved { params: f.params.to_vec(), evaluations: obj.free.len() + 1, ..Resolved::default() };
    if unresolved.is_empty() {
        return out;
    }
    let holdable: Vec<Unresolved> = unresolved
        .iter()
        .copied()
        .filter(|&(j, _, _)| spec.params.get(j).is_some_and(|p| p.lo <= 0.0 && p.hi >= 0.0))
        .collect();
    let cost_free = obj.cost(f.params);
    let mut tries: Vec<Vec<usize>> = vec![holdable.iter().map(|u| u.0).collect()];
    if holdable.len() > 1 {
        let least =
            holdable.iter().max_by(|a, b| (a.2 / a.1.abs().max(1e-300)).total_cmp(&(b.2 / b.1.abs().max(1e-300))));
        tries.extend(least.map(|u| vec![u.0]));
    }
    let mut kept: Option<(Vec<usize>, f64)> = None;
    for held in tries.into_iter().filter(|t| !t.is_empty()) {
        let Some((p, cost, evals)) = refit(f, &spec, &shifted, &held, lm_iterations) else { continue };
        out.evaluations += evals;
        if cost_free.is_finite() && cost <= cost_free * (1.0 + TOLERANCE) {
            out.params = p;
            kept = Some((held, cost / cost_free.max(1e-300) - 1.0));
            break;
        }
    }
    let held_idx: Vec<usize> = kept.as_ref().map(|k| k.0.clone()).unwrap_or_default();
    out.held = held_idx.iter().filter_map(|&j| names.get(j).map(|n| (*n).to_owned())).collect();
    out.warning = Some(warning(&names, &unresolved, kept.as_ref().map(|(h, r)| (h.as_slice(), *r))));
    out
}

/// Refit with the parameters `held` fixed at zero, the others from the fitted set: the
/// parameters, their training cost and the runs spent (`None` when the held set is invalid).
fn refit(
    f: &Fitted<'_>,
    spec: &ModelSpec,
    kin: &[model_core::Kin],
    held: &[usize],
    lm_iterations: usize,
) -> Option<(Vec<f64>, f64, usize)> {
    let mut s = spec.clone();
    for (j, p) in s.params.iter_mut().enumerate() {
        let v = if held.contains(&j) { 0.0 } else { f.params.get(j).copied()?.clamp(p.lo, p.hi) };
        p.start = v;
        if held.contains(&j) {
            p.fixed = true;
        }
    }
    let start = s.start();
    if !f.sim.valid(&start) {
        return None;
    }
    let obj = Objective::new(f.sim, &s, kin, f.y, f.rows, f.scale);
    let r = lm::minimize_reduced(&obj, &start, lm_iterations);
    (r.cost.is_finite() && f.sim.valid(&r.params)).then_some((r.params, r.cost, r.evaluations))
}

/// The warning: every undetermined parameter by name with its interval; which are held at
/// zero (`held`: their indices and the relative rise of the training cost), which are not.
pub fn warning(names: &[&str], unresolved: &[Unresolved], held: Option<(&[usize], f64)>) -> String {
    let base = confidence::warning(names, unresolved).unwrap_or_default();
    let name = |j: usize| names.get(j).copied().unwrap_or("?");
    let (held_idx, rise) = held.unwrap_or((&[], 0.0));
    let free: Vec<&str> = unresolved.iter().filter(|u| !held_idx.contains(&u.0)).map(|u| name(u.0)).collect();
    let held_names: Vec<&str> = held_idx.iter().map(|&j| name(j)).collect();
    let mut out = base.split("; treat").next().unwrap_or_default().to_owned();
    if !held_names.is_empty() {
        out.push_str(&format!(
            "; {} held at 0 and the model refitted (training cost {:+.2} %, within {:.0} %)",
            held_names.join(", "),
            100.0 * rise,
            100.0 * TOLERANCE
        ));
    }
    if !free.is_empty() {
        out.push_str(&format!(
            "; {} not held (zero is outside the range or holding it costs more than {:.0} % of the training cost): \
             treat {} as undetermined",
            free.join(", "),
            100.0 * TOLERANCE,
            if free.len() == 1 { "it" } else { "them" }
        ));
    }
    out
}

#[cfg(test)]
mod tests;
