//! Bounded Levenberg–Marquardt: the `levenberg-marquardt` crate (rust-cv, a MINPACK port)
//! on the free parameters, with the box enforced by a smooth change of variables.
//!
//! Each free parameter's box position `s ∈ [0, 1]` is written `s = (1 + sin θ)/2` with `θ`
//! unconstrained (the MINUIT transform), so every trial point the solver proposes is inside
//! the box. The Jacobian is a forward difference in `θ` through the f32 core, its columns
//! computed in parallel. For the networks and the runs on the whole training part
//! ([`minimize_reduced`]) the solver is handed the problem reduced to one row per parameter
//! ([`crate::numerics::reduce`]).

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::storage::Owned;
use nalgebra::{DMatrix, DVector, Dyn};
use rayon::prelude::*;
use std::sync::atomic::Ordering::Relaxed;

use super::objective::Objective;
use crate::numerics::reduce;

/// Step of the forward difference in θ. The f32 core resolves about 1e-7 of the output, so
/// a step near the square root of that keeps round-off and truncation error balanced.
const FD_STEP: f64 = 3e-4;
/// Residual of an invalid trial point, in units of the output's spread: large enough that
/// the solver rejects the step and shrinks its trust region.
pub(super) const PENALTY: f64 = 1e3;

/// What one local fit did.
#[derive(Clone, Debug, PartialEq)]
pub struct LocalFit {
    pub params: Vec<f64>,
    /// Mean squared scaled residual at `params`.
    pub cost: f64,
    pub evaluations: usize,
    pub termination: String,
}

struct Problem<'a, 'b> {
    obj: &'b Objective<'a>,
    theta: DVector<f64>,
    residuals: Option<DVector<f64>>,
    evaluations: usize,
    /// Jacobians computed so far, and the most allowed (each costs one run per free parameter).
    jacobians: std::sync::atomic::AtomicUsize,
    max_jacobians: usize,
    /// Hand the solver the problem reduced to `n + 1` rows ([`reduce`]).
    reduce: bool,
    /// The point of the last Jacobian and its residuals: the solver's accepted point, to which
    /// it sets the parameters back when it stops after a rejected step (not run again).
    anchor: std::sync::Mutex<Option<Evaluated>>,
}

/// A point of the solver's and its residuals (`None` where the model rejected it).
type Evaluated = (DVector<f64>, Option<DVector<f64>>);

fn unit_of_theta(theta: &[f64]) -> Vec<f64> {
    theta.iter().map(|t| 0.5 * (1.0 + t.sin())).collect()
}

impl Problem<'_, '_> {
    fn eval(&self, theta: &[f64]) -> Option<Vec<f64>> {
        self.obj.residuals(&self.obj.from_unit(&unit_of_theta(theta)))
    }
    fn penalty(&self) -> DVector<f64> {
        DVector::from_element(self.obj.rows.len(), PENALTY)
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_, '_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.theta.copy_from(x);
        let same =
            |a: &DVector<f64>| a.len() == x.len() && a.iter().zip(x.iter()).all(|(a, b)| a.to_bits() == b.to_bits());
        if let Some((_, r)) = self.anchor.get_mut().ok().and_then(|a| a.as_ref()).filter(|(a, _)| same(a)) {
            self.residuals = r.clone();
            return;
        }
        self.evaluations += 1;
        self.residuals = self.eval(x.as_slice()).map(DVector::from_vec);
    }

    fn params(&self) -> DVector<f64> {
        self.theta.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        Some(match (&self.residuals, self.reduce) {
            (Some(r), true) => reduce::reduced_residuals(r.as_slice(), self.theta.len()),
            (None, true) => reduce::reduced_residuals(self.penalty().as_slice(), self.theta.len()),
            (r, false) => r.clone().unwrap_or_else(|| self.penalty()),
        })
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        // Out of budget: stop at the last accepted point (the solver reports `User("jacobian")`).
        if self.jacobians.load(Relaxed) >= self.max_jacobians {
            return None;
        }
        self.jacobians.fetch_add(1, Relaxed);
        if let Ok(mut a) = self.anchor.lock() {
            *a = Some((self.theta.clone(), self.residuals.clone()));
        }
        let base = self.residuals.as_ref()?;
        let n = self.theta.len();
        let cols: Vec<Option<Vec<f64>>> = (0..n)
            .into_par_iter()
            .map(|j| {
                let mut th = self.theta.as_slice().to_vec();
                // Step away from the flat top of sin so the difference is not zero.
                let dir = if th.get(j).is_some_and(|t| t.cos() >= 0.0) { 1.0 } else { -1.0 };
                let h = FD_STEP * dir;
                *th.get_mut(j)? += h;
                let r = self.eval(&th)?;
                Some(r.iter().zip(base.iter()).map(|(a, b)| (a - b) / h).collect())
            })
            .collect();
        // A step that leaves the valid region gives a zero column: that direction is frozen
        // for this iteration.
        let zero = || vec![0.0; base.len()];
        if self.reduce {
            let cols: Vec<Vec<f64>> = cols.into_iter().map(|c| c.unwrap_or_else(zero)).collect();
            let cols: Vec<&[f64]> = cols.iter().map(Vec::as_slice).collect();
            return Some(reduce::reduced_columns(&cols, base.as_slice()));
        }
        let mut jac = DMatrix::zeros(base.len(), n);
        for (j, col) in cols.into_iter().enumerate() {
            if let Some(col) = col {
                jac.column_mut(j).copy_from_slice(&col);
            }
        }
        Some(jac)
    }
}

/// Levenberg–Marquardt from `start` (a full parameter vector), with at most
/// `max_iterations` Jacobians (iterations) and about `10·max_iterations` further residual
/// evaluations. Stops earlier when the relative decrease of the cost or the step falls
/// below 1e-7.
pub fn minimize(obj: &Objective<'_>, start: &[f64], max_iterations: usize) -> LocalFit {
    minimize_with(obj, start, max_iterations, false)
}

/// [`minimize`] with the solver's problem reduced to one row per parameter
/// ([`crate::numerics::reduce`]): the same steps up to round-off, for many rows, where
/// factoring the full Jacobian is a large part of the cost: the networks, and every run on
/// the whole training part (the final run of a global search, the refits of [`super::hold`]
/// and after a delay held at zero). The restarts of a global search, on its window, keep the
/// crate's factorisation: there it is a tenth of the cost or less, and a change of round-off
/// moves which restarts agree (Spencer's model on `ranran_50.csv` then needed a fourth
/// start: slower, not faster).
pub fn minimize_reduced(obj: &Objective<'_>, start: &[f64], max_iterations: usize) -> LocalFit {
    minimize_with(obj, start, max_iterations, true)
}

fn minimize_with(obj: &Objective<'_>, start: &[f64], max_iterations: usize, reduce: bool) -> LocalFit {
    let theta0: Vec<f64> = obj.to_unit(start).iter().map(|s| (2.0 * s - 1.0).clamp(-1.0, 1.0).asin()).collect();
    let n = theta0.len();
    if n == 0 {
        return LocalFit {
            params: start.to_vec(),
            cost: obj.cost(start),
            evaluations: 1,
            termination: "no free parameters".into(),
        };
    }
    let mut problem = Problem {
        obj,
        theta: DVector::from_vec(theta0.clone()),
        residuals: None,
        evaluations: 0,
        jacobians: std::sync::atomic::AtomicUsize::new(0),
        max_jacobians: max_iterations.max(1),
        reduce,
        anchor: std::sync::Mutex::new(None),
    };
    problem.set_params(&DVector::from_vec(theta0));
    let patience = (10 * max_iterations / (n + 1)).max(1);
    let (problem, report) = LevenbergMarquardt::new()
        .with_ftol(1e-7)
        .with_xtol(1e-7)
        .with_gtol(1e-10)
        .with_patience(patience)
        .minimize(problem);
    let params = obj.from_unit(&unit_of_theta(problem.theta.as_slice()));
    // The residuals are those of `params` (set together in `set_params`): their cost is what
    // a run at `params` would give, to the bit, without the run.
    let cost = match &problem.residuals {
        Some(r) => obj.cost_of_residuals(r.as_slice()),
        None => obj.cost(&params),
    };
    let evaluations = problem.evaluations + problem.jacobians.load(Relaxed) * n;
    LocalFit { params, cost, evaluations, termination: format!("{:?}", report.termination) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ident::fit::simulate::{kinematics, simulator};
    use crate::models::search::Scales;
    use crate::models::RateSpec;
    use model_core::Sample;

    /// A Bouc–Wen clutch's noiseless output under two tones, and the search space and rows
    /// of its objective.
    struct Clutch {
        sim: Box<dyn crate::ident::fit::simulate::Simulator>,
        kin: Vec<model_core::Kin>,
        y: Vec<f64>,
        spec: crate::models::search::ModelSpec,
        rows: Vec<usize>,
    }

    /// [`Clutch`] scored from `first_row` on (so a fit can stop before the last sample).
    fn bouc_wen_problem(first_row: usize) -> Clutch {
        let dt = 1e-3f32;
        let samples: Vec<Sample> = (0..4000)
            .map(|i| {
                let t = i as f32 * dt;
                Sample::new((2.0 * t).sin() + 0.5 * (7.0 * t).sin())
            })
            .collect();
        let kin = kinematics(&samples, dt, RateSpec::Backward).unwrap();
        let sim = simulator("bouc_wen", dt).unwrap();
        let mut y = vec![0.0; kin.len()];
        assert!(sim.run(&TRUTH, &kin, &mut y));
        let sc = Scales { x_mean: 0.0, x: 0.8, dx: 1.5, ddx: 4.0, y_mean: 0.0, y: 2.0, u: None, fs: 1000.0 };
        let sp = crate::models::host("bouc_wen").unwrap().spec(&sc, Some(RateSpec::Backward)).unwrap();
        let rows: Vec<usize> = (first_row..kin.len()).collect();
        Clutch { sim, kin, y, spec: sp, rows }
    }

    const TRUTH: [f64; 8] = [3.0, 2.0, 1.0, 1.0, 2.0, 0.4, 0.8, 0.0];
    const START: [f64; 8] = [2.0, 1.0, 2.0, 1.0, 1.5, 0.2, 0.5, 0.1];

    /// Recover a Bouc–Wen parameter set from its own noiseless output, starting away from it.
    #[test]
    fn recovers_a_bouc_wen_set() {
        let c = bouc_wen_problem(0);
        let obj = Objective::new(c.sim.as_ref(), &c.spec, &c.kin, &c.y, &c.rows, 2.0);
        let before = obj.cost(&START);
        let fit = minimize(&obj, &START, 100);
        assert!(fit.cost < 1e-8 && fit.cost < before * 1e-4, "{fit:?} (start cost {before})");
        for (got, want) in fit.params.iter().zip(TRUTH) {
            assert!((got - want).abs() < 1e-2 * (1.0 + want.abs()), "{:?}", fit.params);
        }
    }

    /// The cost a fit reports is taken from its last residuals, not from a run of its own:
    /// it must be the cost of a run at the parameters it reports, to the bit, whether the
    /// fit converged or ran out of iterations part way.
    #[test]
    fn the_reported_cost_is_that_of_the_reported_parameters() {
        for (first_row, iterations) in [(0, 2), (500, 4), (0, 100)] {
            let c = bouc_wen_problem(first_row);
            let obj = Objective::new(c.sim.as_ref(), &c.spec, &c.kin, &c.y, &c.rows, 2.0);
            for reduce in [false, true] {
                let fit = minimize_with(&obj, &START, iterations, reduce);
                assert_eq!(fit.cost.to_bits(), obj.cost(&fit.params).to_bits(), "{fit:?}");
                assert!(fit.cost < obj.cost(&START));
            }
        }
    }
}
