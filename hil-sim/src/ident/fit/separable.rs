//! Separable starts for a model whose output is affine in some of its parameters once the
//! others are fixed ([`crate::models::HostModel::AFFINE`]; tanh, seed 000 eq. 11–12, is
//! affine in `α, c, k, T₀` for fixed `β, γ`): the other free parameters (at most
//! [`MAX_GRID_DIMS`]) on a grid over their box, the affine ones solved by least squares at
//! each grid point (variable projection), and the best few points handed to the global
//! phase's polish ([`super::global`]). The grid ([`Grid`]) and the affine columns
//! ([`affine_columns`]) also serve `diagnose`, which solves the same grid with a candidate
//! term's weight beside the affine parameters (`ident::diagnose::joint_grid`).
//!
//! The swarm searches every parameter at once and can settle in a basin of tanh's rate gain
//! `β` far from the data's (a Bingham-type clutch, `τ₀·tanh(ḃ/ε)` on a power-law static
//! curve: a fitted tanh at 29 % held-out error where the truth's own form gives 4 %); the
//! grid visits every decade of `β`.
//!
//! The affine columns come from the model itself (its f32 core): the output with one affine
//! parameter at 1 and the others at 0, less the output with all at 0.

use rayon::prelude::*;

use super::objective::Objective;
use crate::models::search::ModelSpec;
use crate::numerics::lstsq;

/// Most non-affine free parameters put on a grid.
pub const MAX_GRID_DIMS: usize = 2;
/// Grid points per non-affine parameter (one of them: [`POINTS_1D`]).
const POINTS_2D: [usize; 2] = [16, 9];
const POINTS_1D: usize = 24;
/// Relative singular-value cut-off of the least-squares solve.
const RCOND: f64 = 1e-10;

/// A grid point: the model's full parameter vector and its cost on the objective.
#[derive(Clone, Debug, PartialEq)]
pub struct GridPoint {
    pub params: Vec<f64>,
    pub cost: f64,
}

/// The `keep` best grid points of `obj` (distinct grid cells), each with its affine
/// parameters solved and clamped to their box, best first; empty when the model has no
/// affine parameter free or more than [`MAX_GRID_DIMS`] others.
pub fn starts(obj: &Objective<'_>, affine: &[&str], keep: usize) -> Vec<GridPoint> {
    let n_model = obj.sim.n_params();
    let sp = obj.spec;
    let free: Vec<usize> = obj.free.iter().copied().filter(|&j| j < n_model).collect();
    let Some(grid) = Grid::of(sp, &free, affine, &sp.start()) else { return Vec::new() };
    if keep == 0 {
        return Vec::new();
    }
    let mut found: Vec<GridPoint> = grid
        .points
        .par_iter()
        .filter_map(|p| {
            let p = solve_affine(obj, p.clone(), &grid.lin)?;
            let cost = obj.cost(&p);
            cost.is_finite().then_some(GridPoint { params: p, cost })
        })
        .collect();
    found.sort_by(|a, b| a.cost.total_cmp(&b.cost));
    // One point per neighbourhood of grid cells: the next best elsewhere, not a neighbour.
    let cell = |c: &GridPoint| -> Vec<f64> {
        grid.dims.iter().filter_map(|&j| Some(sp.params.get(j)?.to_unit(*c.params.get(j)?))).collect()
    };
    let widths: Vec<f64> = grid_sizes(grid.dims.len()).iter().map(|&n| 1.5 / n as f64).collect();
    let mut kept: Vec<(Vec<f64>, GridPoint)> = Vec::new();
    for c in found {
        let u = cell(&c);
        let near = |(k, _): &(Vec<f64>, GridPoint)| k.iter().zip(&u).zip(&widths).all(|((a, b), w)| (a - b).abs() < *w);
        if !kept.iter().any(near) {
            kept.push((u, c));
        }
        if kept.len() >= keep {
            break;
        }
    }
    kept.into_iter().map(|(_, c)| c).collect()
}

/// The grid of a model with affine parameters: which free parameters are affine (`lin`),
/// which are put on the grid (`dims`), and the full parameter vector at every grid point
/// (the others as in the base vector it was made from).
pub struct Grid {
    pub lin: Vec<usize>,
    pub dims: Vec<usize>,
    pub points: Vec<Vec<f64>>,
}

impl Grid {
    /// The grid over the free parameters `free` of `sp` that are not in `affine`, about
    /// `base`; `None` when none of `free` is affine, or none or more than
    /// [`MAX_GRID_DIMS`] are not.
    pub fn of(sp: &ModelSpec, free: &[usize], affine: &[&str], base: &[f64]) -> Option<Grid> {
        let (lin, dims): (Vec<usize>, Vec<usize>) =
            free.iter().partition(|&&j| sp.params.get(j).is_some_and(|p| affine.contains(&p.name)));
        if lin.is_empty() || dims.is_empty() || dims.len() > MAX_GRID_DIMS {
            return None;
        }
        let points = cells(dims.len())
            .into_iter()
            .filter_map(|unit| {
                let mut p = base.to_vec();
                for (&j, &u) in dims.iter().zip(&unit) {
                    *p.get_mut(j)? = sp.params.get(j)?.from_unit(u);
                }
                Some(p)
            })
            .collect();
        Some(Grid { lin, dims, points })
    }
}

/// The output with the affine parameters `lin` of `p` all at 0, and each one's column (the
/// output with it at 1 and the others at 0, less that); `run` runs the model. `None` when
/// the model rejects a vector.
pub fn affine_columns(
    run: impl Fn(&[f64]) -> Option<Vec<f64>>,
    p: &[f64],
    lin: &[usize],
) -> Option<(Vec<f64>, Vec<Vec<f64>>)> {
    let mut p = p.to_vec();
    for &j in lin {
        *p.get_mut(j)? = 0.0;
    }
    let zero = run(&p)?;
    let mut cols = Vec::with_capacity(lin.len());
    for &j in lin {
        let mut q = p.clone();
        *q.get_mut(j)? = 1.0;
        let out = run(&q)?;
        cols.push(out.iter().zip(&zero).map(|(a, b)| a - b).collect::<Vec<f64>>());
    }
    Some((zero, cols))
}

fn grid_sizes(dims: usize) -> Vec<usize> {
    if dims == 1 {
        vec![POINTS_1D]
    } else {
        POINTS_2D.iter().copied().take(dims).collect()
    }
}

/// The grid's unit-box positions (cell centres).
fn cells(dims: usize) -> Vec<Vec<f64>> {
    let mut out = vec![Vec::new()];
    for n in grid_sizes(dims) {
        out = out
            .into_iter()
            .flat_map(|u| {
                (0..n).map(move |i| {
                    let mut v = u.clone();
                    v.push((i as f64 + 0.5) / n as f64);
                    v
                })
            })
            .collect();
    }
    out
}

/// `p` with the affine parameters `lin` set by least squares on `obj`'s rows (clamped to
/// their box); `None` when the model rejects `p` or the system is singular.
fn solve_affine(obj: &Objective<'_>, mut p: Vec<f64>, lin: &[usize]) -> Option<Vec<f64>> {
    let n = obj.sim.n_params();
    let kin = obj.kin.get(..obj.end)?;
    let run = |q: &[f64]| -> Option<Vec<f64>> {
        let mut out = vec![0.0; obj.end];
        obj.sim.run(q.get(..n)?, kin, &mut out).then_some(out)
    };
    let (zero, cols) = affine_columns(run, &p, lin)?;
    let target: Vec<f64> = obj.y.iter().take(obj.end).zip(&zero).map(|(y, z)| y - z).collect();
    let (g, b) = lstsq::normal_equations(&cols, &target, obj.rows);
    let theta = lstsq::solve_scaled(g, b, RCOND)?;
    set_clamped(obj.spec, &mut p, lin, theta.as_slice())?;
    Some(p)
}

/// `p` with the affine parameters `lin` set to `values`, each clamped to its box; `None`
/// when a value is not finite.
pub fn set_clamped(sp: &ModelSpec, p: &mut [f64], lin: &[usize], values: &[f64]) -> Option<()> {
    for (&j, &v) in lin.iter().zip(values) {
        let ps = sp.params.get(j)?;
        if !v.is_finite() {
            return None;
        }
        *p.get_mut(j)? = v.clamp(ps.lo, ps.hi);
    }
    Some(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ident::fit::simulate::simulator;
    use crate::models::search::Scales;
    use model_core::Kin;

    /// On a tanh recording whose rate gain sits far from the search's start, the best grid
    /// point, affine part solved, is within a grid cell of the truth's `β` and fits far
    /// better than the start.
    #[test]
    fn the_grid_finds_a_rate_gain_far_from_the_start() {
        let dt = 1e-3;
        let kin: Vec<Kin> = (0..4000)
            .map(|i| {
                let t = i as f64 * dt;
                let w = 2.0 * std::f64::consts::PI * 3.0;
                let (x, v) = (0.5 + 0.4 * (w * t).sin(), 0.4 * w * (w * t).cos());
                Kin::new(x as f32, v as f32, 0.0, 0.0)
            })
            .collect();
        let sim = simulator("tanh", dt as f32).unwrap();
        // The start's β is 1/(rate spread) ≈ 0.19 s; the truth's is 16 times that.
        let truth = [0.8, 3.0, 0.0, 0.01, 3.0, 0.1];
        let mut y = vec![0.0; kin.len()];
        assert!(sim.run(&truth, &kin, &mut y));
        let scales = Scales { x_mean: 0.5, x: 0.28, dx: 5.3, ddx: 100.0, y_mean: 1.6, y: 0.9, u: None, fs: 1e3 };
        let sp = crate::models::host("tanh").unwrap().spec(&scales, None).unwrap();
        let rows: Vec<usize> = (0..kin.len()).collect();
        let obj = Objective::new(sim.as_ref(), &sp, &kin, &y, &rows, 1.0);
        let best = starts(&obj, &["alpha", "c", "k", "t0"], 2);
        assert_eq!(best.len(), 2);
        let beta = best[0].params[1];
        assert!((beta / truth[1]).ln().abs() < 0.6, "{:?}", best[0]);
        assert!(best[0].cost < 0.05 * obj.cost(&sp.start()), "{} vs {}", best[0].cost, obj.cost(&sp.start()));
        assert!(best[0].cost <= best[1].cost);
    }
}
