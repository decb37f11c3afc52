//! The refit from a fitted set: after a delay that ended at the edge of its range is held
//! at zero ([`super::fit`]), the model is refitted from the first search's parameters by a
//! local search instead of a second global one.

use super::objective::Objective;
use super::{identify_variants, lm, operator, restarts, simulate, valid_or_err, FitError, FitOptions, Identified};
use crate::models::search::{ModelSpec, Scales, Strategy};

/// A local search from `warm`, a fitted parameter set of the model (no delay entries) and the
/// variant of the search it came from: Levenberg–Marquardt on the whole training part, over
/// the shape only for a projected model. The strategies without a global phase get
/// [`identify_variants`].
#[allow(clippy::too_many_arguments)]
pub(super) fn warm_fit(
    id: &str,
    sp: &ModelSpec,
    (warm, variant): (&[f64], usize),
    sim: &dyn simulate::Simulator,
    (kin, y, rows): (&[model_core::Kin], &[f64], &[usize]),
    scales: &Scales,
    opts: &FitOptions,
    notes: &restarts::Notes,
) -> Result<Identified, FitError> {
    let v = crate::models::host(sp.id).and_then(|h| h.at_variant(sp, variant, scales));
    let Some(mut v) = v.filter(|v| matches!(v.strategy, Strategy::Global | Strategy::Projected)) else {
        return identify_variants(id, sp, sim, kin, y, rows, scales, opts, notes);
    };
    for (p, w) in v.params.iter_mut().zip(warm) {
        p.start = w.clamp(p.lo, p.hi);
    }
    let (params, evaluations) = if v.strategy == Strategy::Projected {
        let proj = operator::Projected::new(sim, y, rows).ok_or_else(|| FitError::NotFittable(id.to_owned()))?;
        let shape = projected_shape(&v, kin, rows);
        let r = lm::minimize_reduced(
            &Objective::new(&proj, &shape, kin, y, rows, scales.y),
            &shape.start(),
            opts.lm_iterations,
        );
        let full = proj.complete(&r.params, kin).ok_or_else(|| FitError::NoValidSet { model: id.to_owned() })?;
        valid_or_err(id, sim, full, r.evaluations)?
    } else {
        let r = lm::minimize_reduced(&Objective::new(sim, &v, kin, y, rows, scales.y), &v.start(), opts.lm_iterations);
        valid_or_err(id, sim, r.params, r.evaluations)?
    };
    Ok(Identified { params, evaluations, variant })
}

/// The shape search of a projected model: `sp` with the grid / radii spanning the training
/// range (`x_min`, `x_max` held there) and a global strategy.
pub(super) fn projected_shape(sp: &ModelSpec, kin: &[model_core::Kin], rows: &[usize]) -> ModelSpec {
    let end = rows.last().map_or(0, |r| r + 1).min(kin.len());
    let (lo, hi) = operator::x_range(kin, end);
    let pad = 1e-3 * (hi - lo).max(1e-12);
    let mut shape = sp.clone();
    shape.strategy = Strategy::Global;
    for (name, v) in [("x_min", lo - pad), ("x_max", hi + pad)] {
        if let Some(p) = shape.params.iter_mut().find(|p| p.name == name) {
            (p.lo, p.hi, p.start) = (v, v, v);
        }
    }
    shape
}
