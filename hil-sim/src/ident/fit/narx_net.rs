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
//!    (`û(t−1) … û(t−5)`). For each time constant of [`SLOW_GRID`], `κ` and `d` are linear
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
use model_core::Kin;
use nalgebra::storage::Owned;
use nalgebra::{DMatrix, DVector, Dyn};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rayon::prelude::*;

use super::lm::PENALTY;

/// Clamp of the normalised inputs (as the core's `U_LIM`).
const U_LIM: f32 = 1.0e6;

/// Index map of the free block for `h` hidden units: `lin[7], hid_w[7·h], hid_b[h],
/// out_a[h], offset`, the values that follow `u_mean, u_scale, y_mean, y_scale` in the
/// core's flat vector.
#[derive(Clone, Copy, Debug)]
pub struct Shape {
    pub h: usize,
}

impl Shape {
    pub fn n_free(self) -> usize {
        9 * self.h + 8
    }
    fn w(self, j: usize, k: usize) -> usize {
        7 + 7 * j + k
    }
    fn b(self, j: usize) -> usize {
        7 + 7 * self.h + j
    }
    fn a(self, j: usize) -> usize {
        7 + 8 * self.h + j
    }
    fn c(self) -> usize {
        7 + 9 * self.h
    }
}

fn sigmoid(s: f64) -> f64 {
    1.0 / (1.0 + (-s).exp())
}

/// The recording in the core's normalised units.
pub struct Twin {
    pub shape: Shape,
    /// `û(t)` for every sample.
    un: Vec<f64>,
    /// Measured output, normalised.
    yn: Vec<f64>,
    /// Output clamp, normalised.
    lo: f64,
    hi: f64,
}

/// One evaluation of eq. 18–19 at regressors `r` (normalised): the unit activations into
/// `act`; returns the unclamped output and `∂f/∂ŷ(t−1)`.
fn eval(sh: Shape, th: &[f64], r: &[f64; 7], act: &mut [f64]) -> (f64, f64) {
    let mut y = th[sh.c()];
    let mut dfdy = th[0];
    for k in 0..7 {
        y += th[k] * r[k];
    }
    for j in 0..sh.h {
        let mut s = th[sh.b(j)];
        for k in 0..7 {
            s += th[sh.w(j, k)] * r[k];
        }
        let sg = sigmoid(s);
        act[j] = sg;
        y += th[sh.a(j)] * sg;
        dfdy += th[sh.a(j)] * sg * (1.0 - sg) * th[sh.w(j, 0)];
    }
    (y, dfdy)
}

/// `∂f/∂θ` at regressors `r` (activations from [`eval`]), into `g`.
fn direct(sh: Shape, th: &[f64], r: &[f64; 7], act: &[f64], g: &mut [f64]) {
    g[..7].copy_from_slice(r);
    for j in 0..sh.h {
        let sg = act[j];
        let ad = th[sh.a(j)] * sg * (1.0 - sg);
        for k in 0..7 {
            g[sh.w(j, k)] = ad * r[k];
        }
        g[sh.b(j)] = ad;
        g[sh.a(j)] = sg;
    }
    g[sh.c()] = 1.0;
}

impl Twin {
    pub fn new(
        shape: Shape,
        kin: &[Kin],
        y: &[f64],
        (xm, xs): (f64, f64),
        (ym, ys): (f64, f64),
        clamp: (f64, f64),
    ) -> Self {
        // The inputs exactly as the core normalises them (f32), and the constants as it stores them.
        let f = |v: f64| f64::from(v as f32);
        let (xm32, xs32) = (xm as f32, xs as f32);
        let un = kin.iter().map(|k| f64::from(((k.x - xm32) / xs32).clamp(-U_LIM, U_LIM))).collect();
        let (ym, ys) = (f(ym), f(ys));
        let yn = y.iter().map(|v| (v - ym) / ys).collect();
        Self { shape, un, yn, lo: (f(clamp.0) - ym) / ys, hi: (f(clamp.1) - ym) / ys }
    }

    fn u(&self, t: isize) -> f64 {
        let i = t.max(0) as usize;
        self.un.get(i).or(self.un.last()).copied().unwrap_or(0.0)
    }

    fn regressors(&self, t: usize, y_prev: f64) -> [f64; 7] {
        let t = t as isize;
        [y_prev, self.u(t), self.u(t - 1), self.u(t - 2), self.u(t - 3), self.u(t - 4), self.u(t - 5)]
    }

    /// Residuals (model − measurement, normalised) at `rows` (ascending, distinct), running
    /// the network on its own output from the steady start; with `jac`, also their Jacobian
    /// with respect to the entries `cols` of the free block (a clamped output has none).
    /// `None` when the output is not finite.
    pub fn run(
        &self,
        th: &[f64],
        rows: &[usize],
        cols: &[usize],
        mut jac: Option<&mut DMatrix<f64>>,
    ) -> Option<Vec<f64>> {
        let sh = self.shape;
        let n = sh.n_free();
        if th.len() != n {
            return None;
        }
        // The weights as the core stores them (f32): a slow state integrates their rounding.
        let rounded: Vec<f64> = th.iter().map(|v| f64::from(*v as f32)).collect();
        let th = rounded.as_slice();
        let end = rows.last().map_or(0, |r| r + 1).min(self.un.len());
        let mut act = vec![0.0; sh.h];
        let mut g = vec![0.0; n];
        let mut sens = vec![0.0; if jac.is_some() { n } else { 0 }];
        // Steady start: the fixed point of the clamped map at the first input (bisection,
        // as the core's `initial_state`).
        let (mut lo, mut hi) = (self.lo, self.hi);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            let (v, _) = eval(sh, th, &self.regressors(0, mid), &mut act);
            if v.clamp(self.lo, self.hi) > mid {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let r0 = self.regressors(0, 0.5 * (lo + hi));
        let (v0, dfdy0) = eval(sh, th, &r0, &mut act);
        let mut y_prev = v0.clamp(self.lo, self.hi);
        if jac.is_some() && v0 == y_prev && (1.0 - dfdy0).abs() > 1e-9 {
            direct(sh, th, &r0, &act, &mut g);
            let k = 1.0 / (1.0 - dfdy0);
            for (s, gi) in sens.iter_mut().zip(&g) {
                *s = gi * k;
            }
        }
        let mut out = Vec::with_capacity(rows.len());
        let mut next = rows.iter().peekable();
        for t in 0..end {
            let r = self.regressors(t, y_prev);
            let (v, dfdy) = eval(sh, th, &r, &mut act);
            let y = v.clamp(self.lo, self.hi);
            if !y.is_finite() {
                return None;
            }
            if jac.is_some() {
                if v == y {
                    direct(sh, th, &r, &act, &mut g);
                    for (s, gi) in sens.iter_mut().zip(&g) {
                        *s = gi + dfdy * *s;
                    }
                } else {
                    sens.iter_mut().for_each(|s| *s = 0.0);
                }
            }
            if next.peek() == Some(&&t) {
                next.next();
                let row = out.len();
                out.push(y - self.yn.get(t).copied().unwrap_or(0.0));
                if let Some(j) = jac.as_deref_mut() {
                    for (c, &i) in cols.iter().enumerate() {
                        j[(row, c)] = sens.get(i).copied().unwrap_or(0.0);
                    }
                }
            }
            y_prev = y;
        }
        Some(out)
    }

    /// Mean squared residual at `rows`.
    pub fn cost(&self, th: &[f64], rows: &[usize]) -> f64 {
        match self.run(th, rows, &[], None) {
            Some(r) if !r.is_empty() => r.iter().map(|v| v * v).sum::<f64>() / r.len() as f64,
            _ => f64::INFINITY,
        }
    }
}

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

    fn residuals(&self) -> Option<DVector<f64>> {
        Some(self.res.clone().unwrap_or_else(|| DVector::from_element(self.rows.len(), PENALTY)))
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        if self.jacobians.get() >= self.max_jacobians {
            return None;
        }
        self.jacobians.set(self.jacobians.get() + 1);
        let mut j = DMatrix::zeros(self.rows.len(), self.cols.len());
        let th = self.theta(self.x.as_slice());
        self.twin.run(&th, self.rows, self.cols, Some(&mut j))?;
        Some(j)
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
mod tests {
    use super::*;
    use crate::ident::fit::simulate::simulator_of;
    use model_core::models::narx::Narx;

    const H: usize = 4;

    fn input(n: usize) -> Vec<Kin> {
        (0..n)
            .map(|i| {
                let t = i as f32 * 1e-3;
                Kin::new(0.4 + 0.3 * (9.0 * t).sin() + 0.2 * (23.0 * t).sin() + 0.05 * (71.0 * t).cos(), 0.0, 0.0, 0.0)
            })
            .collect()
    }

    fn random_theta(sh: Shape, rng: &mut StdRng) -> Vec<f64> {
        let mut th: Vec<f64> = (0..sh.n_free()).map(|_| rng.random_range(-0.6..0.6)).collect();
        th[0] = 0.7;
        th
    }

    /// The f32 core's output for free block `th` (normalisation `(0.4, 0.3)`, `(1.0, 2.0)`).
    fn core(th: &[f64], kin: &[Kin]) -> Vec<f64> {
        let mut p = vec![0.4, 0.3, 1.0, 2.0];
        p.extend_from_slice(th);
        p.extend([-9.0, 11.0]);
        let mut out = vec![0.0; kin.len()];
        assert!(simulator_of::<Narx<H>>(1e-3).run(&p, kin, &mut out));
        out
    }

    fn twin(kin: &[Kin], y: &[f64]) -> Twin {
        Twin::new(Shape { h: H }, kin, y, (0.4, 0.3), (1.0, 2.0), (-9.0, 11.0))
    }

    #[test]
    fn twin_runs_like_the_core() {
        let kin = input(3000);
        let mut rng = StdRng::seed_from_u64(3);
        let th = random_theta(Shape { h: H }, &mut rng);
        let y = core(&th, &kin);
        let rows: Vec<usize> = (0..kin.len()).collect();
        let r = twin(&kin, &y).run(&th, &rows, &[], None).unwrap();
        // Residuals against the core's own output: f32 rounding only.
        assert!(r.iter().all(|e| e.abs() < 1e-5), "{:?}", r.iter().fold(0.0f64, |m, e| m.max(e.abs())));
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let kin = input(1500);
        let mut rng = StdRng::seed_from_u64(5);
        let sh = Shape { h: H };
        let th = random_theta(sh, &mut rng);
        let y = vec![0.0; kin.len()];
        // No clamp in reach: the output is differentiable everywhere.
        let tw = Twin::new(sh, &kin, &y, (0.4, 0.3), (1.0, 2.0), (-1e3, 1e3));
        let rows: Vec<usize> = (0..kin.len()).step_by(7).collect();
        let cols: Vec<usize> = (0..sh.n_free()).collect();
        let mut jac = DMatrix::zeros(rows.len(), cols.len());
        tw.run(&th, &rows, &cols, Some(&mut jac)).unwrap();
        for c in cols {
            // Central difference, the step well above the f32 rounding of the weights.
            let h = 1e-3;
            let mut plus = th.clone();
            plus[c] += h;
            let mut minus = th.clone();
            minus[c] -= h;
            let (rp, rm) = (tw.run(&plus, &rows, &[], None).unwrap(), tw.run(&minus, &rows, &[], None).unwrap());
            for (i, (a, b)) in rp.iter().zip(&rm).enumerate() {
                let fd = (a - b) / (2.0 * h);
                let an = jac[(i, c)];
                assert!((fd - an).abs() < 2e-3 * (1.0 + an.abs()), "column {c}, row {i}: {an} vs {fd}");
            }
        }
    }

    #[test]
    fn slow_state_is_written_exactly() {
        // G on û(t) … û(t−4) (units 0..2), then the slow state: the network must run as
        // G(t) + s(t) with s(t) = a·s(t−1) + κ·G(t−1) + d from its steady start.
        let kin = input(4000);
        let sh = Shape { h: H };
        let mut rng = StdRng::seed_from_u64(9);
        let mut g = vec![0.0; sh.n_free()];
        for c in static_cols(sh, H / 2, 5) {
            g[c] = rng.random_range(-0.8..0.8);
        }
        // A measurement with a slow drift, so the least squares pick a slow state.
        let rows: Vec<usize> = (0..kin.len()).collect();
        let tw0 = twin(&kin, &vec![0.0; kin.len()]);
        let gv = outputs(&tw0, &g, kin.len()).unwrap();
        let mut s = 0.0;
        let y: Vec<f64> = gv
            .iter()
            .map(|gt| {
                let v = 1.0 + 2.0 * (gt + s);
                s = 0.999 * s - 0.0004 * gt;
                v
            })
            .collect();
        let tw = twin(&kin, &y);
        let th = with_slow_state(&tw, &g, H / 2, &rows, &[10.0, 1000.0, 3000.0]).unwrap();
        let a = th[0];
        assert!(a > 0.99, "a = {a}");
        let out = outputs(&tw, &th, kin.len()).unwrap();
        // s = ŷ − G must follow s(t) = a·s(t−1) + κ·G(t−1) + d with one constant d (κ from
        // the shifted copy's output weight −(a − κ)·aⱼ); up to the f32 rounding of the weights.
        let kappa = a + th[sh.a(H / 2)] / g[sh.a(0)];
        let d: Vec<f64> =
            (1..kin.len()).map(|t| out[t] - gv[t] - a * (out[t - 1] - gv[t - 1]) - kappa * gv[t - 1]).collect();
        assert!(d.iter().all(|v| (v - d[0]).abs() < 1e-6), "d varies: {:?}", (d[0], d.last()));
    }

    #[test]
    fn learns_a_network_from_its_output() {
        // Data from a known 4-unit network; the training must reproduce it closely on a
        // stretch it was not trained on.
        let kin = input(6000);
        let mut rng = StdRng::seed_from_u64(11);
        let sh = Shape { h: H };
        let mut truth = random_theta(sh, &mut rng);
        truth[0] = 0.5;
        let y = core(&truth, &kin);
        let tw = twin(&kin, &y);
        let rows: Vec<usize> = (0..4500).collect();
        let held: Vec<usize> = (4500..6000).collect();
        let score = |th: &[f64], at: &[usize]| tw.cost(th, at);
        let net = train(&tw, &rows, &Effort::default(), 1, &score).unwrap();
        let var = {
            let m = held.iter().map(|&i| (y[i] - 1.0) / 2.0).sum::<f64>() / held.len() as f64;
            held.iter().map(|&i| ((y[i] - 1.0) / 2.0 - m).powi(2)).sum::<f64>() / held.len() as f64
        };
        let mse = tw.cost(&net.theta, &held);
        assert!(mse < 1e-3 * var, "held-out MSE {mse} against variance {var}");
    }
}
