//! Training of the NARX model (seed 000 eq. 18–19) on the host.
//!
//! The network is trained in simulation mode (it runs on its own past output, as on the
//! board) by Levenberg–Marquardt (the `levenberg-marquardt` crate, a MINPACK port) with
//! the exact Jacobian: an f64 twin of the core's evaluator carries the sensitivities
//! `∂ŷ(t)/∂θ = ∂f/∂θ + ∂f/∂ŷ(t−1)·∂ŷ(t−1)/∂θ` along the recursion (forward-mode, one
//! pass over the data instead of one run per weight), and through the steady start
//! (implicit function theorem at the fixed point).
//!
//! The twin evaluates the weights rounded to f32 and the inputs normalised in f32, as the
//! core stores and computes them: a slow state (below) integrates the rounding of its
//! weights over thousands of steps, so the optimiser has to see it.
//!
//! Procedure (everything in the core's normalised units), per random restart:
//!
//! 1. **Static part.** A feed-forward network `G` on the present and past inputs (no
//!    output feedback: a regression, no recursion), from sigmoids spread over the input
//!    range whose output layer is solved in closed form, then trained by LM.
//! 2. **Two starts.** (a) `G` with all units on `û(t) … û(t−5)`, no feedback. (b) `G` with
//!    half of the units on `û(t) … û(t−4)`, plus a slow state `s = ŷ − G` carried by the
//!    output feedback: a leaky integral of `G`, `s(t) = a·s(t−1) + κ·G(t−1) + d` (on a
//!    clutch: the fluid warming up under its own slip power, its yield stress falling).
//!    Written into eq. 18–19 exactly: `ŷ(t) = G(t) + a·ŷ(t−1) − (a − κ)·G(t−1) + d`, the
//!    other half of the units being `G`'s units on the inputs one sample later
//!    (`û(t−1) … û(t−5)`). For each time constant of `SLOW_GRID`, `κ` and `d` are linear
//!    least squares; the best fit is the start.
//! 3. **Simulation mode.** Every weight is then trained by LM on the fit block (the first
//!    part of the training data), the model running on its own output.
//! 4. **Selection.** Every candidate (both starts of every restart, before and after step 3)
//!    is scored by the f32 core on the validation block (the rest of the training data,
//!    after the fit block: the model must carry on beyond what it was trained on, as it
//!    must on the held-out part). The best is refined by LM on the whole training part,
//!    and the refinement kept when the core scores it better there.

use std::cell::Cell;

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};

use nalgebra::storage::Owned;
use nalgebra::{DMatrix, DVector, Dyn};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rayon::prelude::*;

use super::lm::PENALTY;
use crate::numerics::reduce;

mod twin;

use twin::eval;
pub use twin::{Shape, Twin};

/// Least-squares problem over the columns `cols` of the free block.
struct Problem<'a> {
    twin: &'a Twin,
    rows: &'a [usize],
    cols: &'a [usize],
    full: Vec<f64>,
    x: DVector<f64>,
    res: Option<DVector<f64>>,
    /// Residual evaluations and Jacobians so far; the most Jacobians allowed.
    evaluations: usize,
    jacobians: Cell<usize>,
    max_jacobians: usize,
}

impl Problem<'_> {
    fn theta(&self, x: &[f64]) -> Vec<f64> {
        let mut th = self.full.clone();
        for (&i, v) in self.cols.iter().zip(x) {
            if let Some(t) = th.get_mut(i) {
                *t = *v;
            }
        }
        th
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.x.copy_from(x);
        self.evaluations += 1;
        let th = self.theta(x.as_slice());
        self.res = self.twin.run(&th, self.rows, self.cols, None).map(DVector::from_vec);
    }

    fn params(&self) -> DVector<f64> {
        self.x.clone()
    }

    // The solver sees the problem reduced to `n + 1` rows ([`reduce`]): the same steps,
    // without a factorisation of the rows × weights Jacobian per iteration.
    fn residuals(&self) -> Option<DVector<f64>> {
        let n = self.cols.len();
        Some(match &self.res {
            Some(r) => reduce::reduced_residuals(r.as_slice(), n),
            None => reduce::reduced_residuals(&vec![PENALTY; self.rows.len()], n),
        })
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        if self.jacobians.get() >= self.max_jacobians {
            return None;
        }
        self.jacobians.set(self.jacobians.get() + 1);
        let mut j = DMatrix::zeros(self.rows.len(), self.cols.len());
        let th = self.theta(self.x.as_slice());
        self.twin.run(&th, self.rows, self.cols, Some(&mut j))?;
        Some(reduce::reduced(&j, self.res.as_ref()?.as_slice()))
    }
}

/// LM over the entries `cols` of free block `th` on `rows`, at most `iterations` Jacobians
/// (and about ten residual evaluations per iteration). Returns the new free block and the
/// number of network runs.
fn lm(twin: &Twin, th: &[f64], rows: &[usize], cols: &[usize], iterations: usize) -> (Vec<f64>, usize) {
    let x0: Vec<f64> = cols.iter().filter_map(|&i| th.get(i).copied()).collect();
    let mut p = Problem {
        twin,
        rows,
        cols,
        full: th.to_vec(),
        x: DVector::from_vec(x0.clone()),
        res: None,
        evaluations: 0,
        jacobians: Cell::new(0),
        max_jacobians: iterations.max(1),
    };
    p.set_params(&DVector::from_vec(x0));
    let (p, _) = LevenbergMarquardt::new()
        .with_ftol(1e-8)
        .with_xtol(1e-8)
        .with_gtol(1e-12)
        .with_patience((10 * iterations / (cols.len() + 1)).max(2))
        .minimize(p);
    (p.theta(p.x.as_slice()), p.evaluations + p.jacobians.get())
}

/// Outputs of the network (normalised, clamped) at samples `0..end`.
fn outputs(twin: &Twin, th: &[f64], end: usize) -> Option<Vec<f64>> {
    let rows: Vec<usize> = (0..end).collect();
    let r = twin.run(th, &rows, &[], None)?;
    Some(r.iter().zip(&twin.yn).map(|(e, y)| e + y).collect())
}

/// Columns of the feed-forward part on the inputs `û(t) … û(t−taps+1)` of the first `units` units.
fn static_cols(sh: Shape, units: usize, taps: usize) -> Vec<usize> {
    let mut c: Vec<usize> = (1..=taps).collect();
    for j in 0..units {
        c.extend((1..=taps).map(|k| sh.w(j, k)));
        c.push(sh.b(j));
        c.push(sh.a(j));
    }
    c.push(sh.c());
    c
}

/// Step 1: the static network `G` with `units` sigmoids on `taps` inputs, trained on `rows`.
fn static_part(
    twin: &Twin,
    units: usize,
    taps: usize,
    rows: &[usize],
    iterations: usize,
    rng: &mut StdRng,
) -> Option<(Vec<f64>, usize)> {
    let sh = twin.shape;
    let mut th = vec![0.0; sh.n_free()];
    // Sigmoids spread over the input range (the inputs are normalised), on the present
    // input with small weights on the past ones.
    for j in 0..units {
        let gain = rng.random_range(1.0..4.0) * if rng.random::<bool>() { 1.0 } else { -1.0 };
        let centre = rng.random_range(-2.0..2.0);
        for k in 1..=taps {
            th[sh.w(j, k)] = if k == 1 { gain } else { 0.1 * gain * rng.random_range(-1.0..1.0) };
        }
        th[sh.b(j)] = -gain * centre;
    }
    // Output layer in closed form (the network is linear in it).
    let end = rows.last().map_or(0, |r| r + 1);
    let mut cols: Vec<Vec<f64>> =
        (0..taps).map(|k| (0..end).map(|t| twin.u(t as isize - k as isize)).collect()).collect();
    let mut act = vec![0.0; sh.h];
    let mut units_out: Vec<Vec<f64>> = vec![Vec::with_capacity(end); units];
    for t in 0..end {
        eval(sh, &th, &twin.regressors(t, 0.0), &mut act);
        for (o, a) in units_out.iter_mut().zip(&act) {
            o.push(*a);
        }
    }
    cols.extend(units_out);
    cols.push(vec![1.0; end]);
    let (gram, atb) = crate::numerics::nnls::normal_equations(&cols, &twin.yn, rows);
    let sol = crate::numerics::nnls::solve(&gram, &atb, &vec![false; cols.len()])?;
    for k in 0..taps {
        th[1 + k] = sol[k];
    }
    for j in 0..units {
        th[sh.a(j)] = sol[taps + j];
    }
    th[sh.c()] = sol[taps + units];
    let (th, runs) = lm(twin, &th, rows, &static_cols(sh, units, taps), iterations);
    Some((th, runs + 1))
}

/// Step 2: the slow state on top of `G` (units `0..units` on `û(t) … û(t−4)`): the best
/// time constant of `grid` (samples) by least squares on `rows`, written into eq. 18–19
/// with the shifted copy of `G` in units `units..2·units`.
fn with_slow_state(twin: &Twin, g: &[f64], units: usize, rows: &[usize], grid: &[f64]) -> Option<Vec<f64>> {
    let sh = twin.shape;
    let end = rows.last().map_or(0, |r| r + 1);
    let gv = outputs(twin, g, end)?;
    let e: Vec<f64> = twin.yn.iter().zip(&gv).map(|(y, g)| y - g).collect();
    let mut best: Option<(f64, f64, f64, f64)> = None;
    for &tau in grid {
        let a = (-1.0 / tau).exp();
        // The leaky mean (1 − a)·Σ aᵏ·G(t−1−k), from its steady value at the start.
        let mut p = gv.first().copied().unwrap_or(0.0) / (1.0 - a);
        let phi: Vec<f64> = gv
            .iter()
            .map(|g| {
                let v = (1.0 - a) * p;
                p = a * p + g;
                v
            })
            .collect();
        let cols = [phi, vec![1.0; end]];
        let (gram, atb) = crate::numerics::nnls::normal_equations(&cols, &e, rows);
        let sol = crate::numerics::nnls::solve(&gram, &atb, &[false, false])?;
        let cost: f64 = rows.iter().map(|&t| (e[t] - sol[0] * cols[0][t] - sol[1]).powi(2)).sum();
        if best.is_none_or(|b| cost < b.0) {
            best = Some((cost, a, sol[0] * (1.0 - a), sol[1]));
        }
    }
    // s = κ'·ψ + d' with the leaky mean ψ: κ = κ'·(1 − a), d = d'·(1 − a); G(t−1) enters
    // ŷ(t) with the factor −m = −(a − κ).
    let (_, a, kappa, d1) = best?;
    let m = a - kappa;
    let mut th = g.to_vec();
    th[0] = a;
    for k in (2..=6).rev() {
        th[k] = g[k] - m * g[k - 1];
    }
    for j in 0..units {
        for k in 1..=5 {
            th[sh.w(units + j, k + 1)] = g[sh.w(j, k)];
        }
        th[sh.b(units + j)] = g[sh.b(j)];
        th[sh.a(units + j)] = -m * g[sh.a(j)];
    }
    th[sh.c()] = g[sh.c()] * (1.0 - m) + d1 * (1.0 - a);
    Some(th)
}

/// How much work the training does.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Effort {
    /// Random restarts; each gives two candidates (with and without the slow state).
    pub restarts: usize,
    /// LM iterations (Jacobians) of the static part, of the simulation-mode training on the
    /// fit block, and of the refinement on the whole training part.
    pub static_iterations: usize,
    pub sim_iterations: usize,
    pub final_iterations: usize,
    /// Most residual rows an LM problem has (longer stretches are subsampled evenly; the
    /// network still runs over every sample).
    pub max_rows: usize,
    /// Share of the training rows in the validation block (the last ones).
    pub validation: f64,
}

impl Default for Effort {
    /// About 5 s for the 8-unit network on the 28 000 training samples of
    /// `hil-sim simulate --scenario multisine` on two cores.
    fn default() -> Self {
        Self {
            restarts: 2,
            static_iterations: 30,
            sim_iterations: 25,
            final_iterations: 10,
            max_rows: 4000,
            validation: 0.2,
        }
    }
}

/// Time constants of the slow state tried, as multiples of the fit block's length. Longer
/// ones are not tried: their steady value is `(κ·G + d)/(1 − a)`, and with `1 − a` near
/// the f32 resolution of the board's feedback weight the core's rounding, integrated over
/// `1/(1 − a)` steps, becomes a visible drift (measured: 10× and 30× the fit block scored
/// worse on the validation block in f32 than in f64).
const SLOW_GRID: [f64; 5] = [0.03, 0.1, 0.3, 1.0, 3.0];

/// Longest time constant of the slow state, samples (`1 − a ≥ 10⁻⁵`, ≈ 170 f32 steps
/// below 1).
const SLOW_MAX: f64 = 1.0e5;

fn subsample(rows: &[usize], max: usize) -> Vec<usize> {
    let step = rows.len().div_ceil(max.max(1)).max(1);
    rows.iter().step_by(step).copied().collect()
}

/// A trained network.
#[derive(Clone, Debug)]
pub struct Net {
    /// The free block.
    pub theta: Vec<f64>,
    /// Network runs spent (residual evaluations and Jacobian passes).
    pub runs: usize,
    /// Mean squared normalised residual of the f32 core on the validation block.
    pub validation: f64,
    /// Whether it came from the slow-state start.
    pub slow: bool,
}

/// Train the network of `twin` on `rows` (ascending, the training part); `score(θ, rows)` is
/// the f32 core's mean squared normalised residual at `rows` for free block `θ` (the model
/// running from the first sample). `None` when no candidate is valid.
pub fn train(
    twin: &Twin,
    rows: &[usize],
    effort: &Effort,
    seed: u64,
    score: &(dyn Fn(&[f64], &[usize]) -> f64 + Sync),
) -> Option<Net> {
    let h = twin.shape.h;
    let n_val = ((rows.len() as f64) * effort.validation).round() as usize;
    let (fit_rows, val_rows) =
        if n_val >= 200 && rows.len() - n_val >= 200 { rows.split_at(rows.len() - n_val) } else { (rows, rows) };
    let fit_sub = subsample(fit_rows, effort.max_rows);
    let grid: Vec<f64> =
        SLOW_GRID.iter().map(|f| f * fit_rows.len() as f64).filter(|tau| *tau >= 1.0 && *tau <= SLOW_MAX).collect();
    let all: Vec<usize> = (0..twin.shape.n_free()).collect();
    let starts: Vec<(u64, bool)> =
        (0..effort.restarts.max(1) as u64).flat_map(|k| [(k, false), (k, true)]).filter(|s| !s.1 || h >= 2).collect();
    let cands: Vec<Net> = starts
        .par_iter()
        .filter_map(|&(k, slow)| {
            let mut rng = StdRng::seed_from_u64(seed.wrapping_mul(1000).wrapping_add(k));
            let (start, runs) = if slow {
                let (g, runs) = static_part(twin, h / 2, 5, &fit_sub, effort.static_iterations, &mut rng)?;
                (with_slow_state(twin, &g, h / 2, fit_rows, &grid)?, runs + 1)
            } else {
                static_part(twin, h, 6, &fit_sub, effort.static_iterations, &mut rng)?
            };
            let (trained, r) = lm(twin, &start, &fit_sub, &all, effort.sim_iterations);
            // The start is a valid model too: the better of the two on the validation block.
            let (theta, validation) = [start, trained]
                .into_iter()
                .map(|t| {
                    let v = score(&t, val_rows);
                    (t, v)
                })
                .min_by(|a, b| a.1.total_cmp(&b.1))?;
            validation.is_finite().then_some(Net { theta, runs: runs + r + 2, validation, slow })
        })
        .collect();
    let runs: usize = cands.iter().map(|c| c.runs).sum();
    let best = cands.into_iter().min_by(|a, b| a.validation.total_cmp(&b.validation))?;
    if effort.final_iterations == 0 || fit_rows.len() == rows.len() {
        return Some(Net { runs, ..best });
    }
    // Refine the winner on the whole training part (the validation block is the most
    // recent data); kept when the core scores it better there.
    let all_sub = subsample(rows, effort.max_rows);
    let (theta, r) = lm(twin, &best.theta, &all_sub, &all, effort.final_iterations);
    let runs = runs + r + 2;
    if score(&theta, rows) <= score(&best.theta, rows) {
        let validation = score(&theta, val_rows);
        Some(Net { theta, runs: runs + 1, validation, slow: best.slow })
    } else {
        Some(Net { runs, ..best })
    }
}
#[cfg(test)]
mod tests;
