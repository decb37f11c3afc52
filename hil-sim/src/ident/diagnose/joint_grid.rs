//! Where a candidate's refit starts on a base whose output is affine in some of its
//! parameters once the others are fixed ([`crate::models::HostModel::AFFINE`]; tanh, seed
//! 000 eq. 11): the others on the base fit's grid ([`crate::ident::fit::separable`]), the
//! affine ones and every additive term's weight solved jointly by least squares at each grid
//! point, the best point kept for each candidate.
//!
//! The base fit's grid finds the lowest training error of the base alone; with a concealed
//! rate term, tanh's rate gain bends to take it up (`tanh(β·ḃ)` holds a cubic), and a refit
//! of the term started there stays in that basin (the bench's fresh34 `324029177`, a
//! `|ḃ|·ḃ` term on a Bingham-type clutch, and fresh35 `342013861`, on a Kwok clutch, were
//! named nothing). The candidate's own grid start puts the base and the term at their
//! joint optimum.

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

use super::augment::{Fitted, Problem, Term};
use super::candidates::Candidate;
use crate::ident::fit::separable::{affine_columns, set_clamped, Grid};
use crate::numerics::lstsq;

/// Most training rows the grid's least squares use (every k-th row beyond).
const MAX_ROWS: usize = 8000;
/// Relative singular-value cut-off of the solves.
const RCOND: f64 = 1e-10;

/// A sum of squared errors and the values it was reached with (`None`: not solved).
type Solved = Option<(f64, Vec<f64>)>;

/// For each of `cands` (by index; `None` for one in `used`, one with an input transform or a
/// grid of its own, or a term that is not additive) the base parameters θ at the grid point
/// where the base and its terms fit the training rows best; all `None` when the base has no
/// affine parameter or the reference a term that is not additive.
pub fn starts(prob: &Problem<'_>, cands: &[Candidate], reference: &Fitted, used: &[usize]) -> Vec<Option<Vec<f64>>> {
    let pieces: Vec<Option<Vec<Term>>> = cands
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let piece = c.grid.first().filter(|_| c.grid.len() == 1 && !used.contains(&k)).map(|&g| (c.build)(g))?;
            piece.transform.is_none().then_some(piece.terms)
        })
        .collect();
    best_points(prob, reference, &pieces).into_iter().map(|b| b.map(|(_, theta)| theta)).collect()
}

/// For each of `pieces` (terms added to `reference`'s; `None`, an empty list or a term that
/// is not additive: skipped) the grid point where the base and all the terms fit the
/// training rows best: its sum of squared errors (on at most [`MAX_ROWS`] of the rows) and
/// the base parameters θ there; all `None` when the base has no affine parameter or the
/// reference a term that is not additive.
fn best_points(prob: &Problem<'_>, reference: &Fitted, pieces: &[Option<Vec<Term>>]) -> Vec<Solved> {
    let none = vec![None; pieces.len()];
    let affine = crate::models::host(prob.spec.id).map_or(&[][..], |h| h.affine);
    if affine.is_empty() || !reference.terms.iter().all(Term::is_additive) {
        return none;
    }
    let n_model = prob.sim.n_params();
    let free: Vec<usize> = prob.spec.free().into_iter().filter(|&j| j < n_model).collect();
    let Some(grid) = Grid::of(prob.spec, &free, affine, &reference.theta) else { return none };
    let Some(fed) = prob.fed(&reference.transforms) else { return none };
    let (x, kin) = (&fed.x, &fed.kin);
    // Each piece's columns, by index into one matrix of them all.
    let mut columns: Vec<Vec<f64>> = Vec::new();
    let mut of_piece: Vec<Option<Vec<usize>>> = Vec::with_capacity(pieces.len());
    for terms in pieces {
        let terms = terms.as_ref().filter(|t| !t.is_empty() && t.iter().all(Term::is_additive));
        of_piece.push(terms.map(|terms| {
            let at = columns.len();
            let terms = prob.through(terms.clone(), &reference.transforms, x);
            columns.extend(terms.into_iter().map(|t| t.values));
            (at..columns.len()).collect()
        }));
    }
    if of_piece.iter().all(Option::is_none) {
        return none;
    }
    let step = prob.train.len().div_ceil(MAX_ROWS).max(1);
    let rows: Vec<usize> = prob.train.iter().copied().step_by(step).collect();
    let on_rows =
        |v: &[f64]| DVector::from_iterator(rows.len(), rows.iter().map(|&i| v.get(i).copied().unwrap_or(0.0)));
    let matrix =
        |cols: &[&[f64]]| DMatrix::from_fn(rows.len(), cols.len(), |r, c| cols[c].get(rows[r]).copied().unwrap_or(0.0));
    let fixed: Vec<&[f64]> = reference.terms.iter().map(|t| t.values.as_slice()).collect();
    let piece_cols: Vec<&[f64]> = columns.iter().map(Vec::as_slice).collect();
    let (c_mat, y) = (matrix(&piece_cols), on_rows(&prob.data.output));
    let g_cc = c_mat.tr_mul(&c_mat);
    let run = |q: &[f64]| prob.run_kin(q, kin);
    // At each grid point, every piece's training SSE and solved affine values.
    let per_point: Vec<(usize, Vec<Solved>)> = grid
        .points
        .par_iter()
        .enumerate()
        .filter_map(|(at, p)| {
            let (zero, lin_cols) = affine_columns(run, p, &grid.lin)?;
            let a_cols: Vec<&[f64]> = lin_cols.iter().map(Vec::as_slice).chain(fixed.iter().copied()).collect();
            let a = matrix(&a_cols);
            let t = &y - on_rows(&zero);
            let (g_aa, g_ac, a_t, c_t) = (a.tr_mul(&a), a.tr_mul(&c_mat), a.tr_mul(&t), c_mat.tr_mul(&t));
            let tt = t.dot(&t);
            let solved = of_piece
                .iter()
                .map(|j| {
                    let j = j.as_ref()?;
                    let (na, n) = (a_cols.len(), a_cols.len() + j.len());
                    let g = DMatrix::from_fn(n, n, |r, c| match (r < na, c < na) {
                        (true, true) => g_aa[(r, c)],
                        (true, false) => g_ac[(r, j[c - na])],
                        (false, true) => g_ac[(c, j[r - na])],
                        (false, false) => g_cc[(j[r - na], j[c - na])],
                    });
                    let b = DVector::from_fn(n, |r, _| if r < na { a_t[r] } else { c_t[j[r - na]] });
                    let th = lstsq::solve_scaled(g.clone(), b.clone(), RCOND)?;
                    let sse = tt - 2.0 * th.dot(&b) + (&g * &th).dot(&th);
                    sse.is_finite().then(|| (sse, th.iter().take(grid.lin.len()).copied().collect()))
                })
                .collect();
            Some((at, solved))
        })
        .collect();
    (0..pieces.len())
        .map(|k| {
            let (at, sse, lin) = per_point
                .iter()
                .filter_map(|(at, s)| s.get(k)?.as_ref().map(|(sse, lin)| (*at, *sse, lin)))
                .min_by(|a, b| a.1.total_cmp(&b.1))?;
            let mut theta = grid.points.get(at)?.clone();
            set_clamped(prob.spec, &mut theta, &grid.lin, lin)?;
            prob.sim.valid(&theta).then_some((sse, theta))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ident::diagnose::tests::with_noise;
    use crate::ident::fit::simulate::{simulator, Simulator};
    use crate::ident::fit::Dataset;
    use crate::models::search::ModelSpec;
    use crate::models::RateSpec;
    use rand::SeedableRng;

    /// tanh's search space on `data`'s scales.
    fn spec_of(data: &Dataset) -> ModelSpec {
        crate::models::host("tanh").unwrap().spec(&data.scales(), None).unwrap()
    }

    /// The refit problem of `sim` on `data`, trained on its training part.
    fn problem<'a>(data: &'a Dataset, sim: &'a dyn Simulator, spec: &'a ModelSpec) -> Problem<'a> {
        let train = (0..data.train_end).collect();
        Problem::new(data, (sim, spec), RateSpec::Backward, train, 100.0)
    }

    /// A tanh clutch (seed 000 eq. 11) with a `|ḃ|·ḃ` term at 5 % of its span, under two
    /// tones, and a reference whose rate gain sits 30 times off the truth's (a base that
    /// settled in another basin): the `|rate|·rate` candidate's start has the truth's rate
    /// gain to within a grid cell, and with the term solved there it fits the training part
    /// far better than the reference's θ with the term.
    #[test]
    fn a_rate_term_starts_at_the_joint_optimum_of_base_and_term() {
        let (dt, n) = (1e-3, 8000);
        let x: Vec<f64> = (0..n)
            .map(|i| {
                let t = i as f64 * dt;
                0.4 * (2.0 * std::f64::consts::PI * 3.0 * t).sin() + 0.2 * (2.0 * std::f64::consts::PI * 7.7 * t).sin()
            })
            .collect();
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        let sim = simulator("tanh", dt as f32).unwrap();
        let truth = [0.8, 0.3, 0.0, 0.01, 3.0, 0.1];
        let kin = {
            let blank = with_noise(x.clone(), &vec![0.0; n], &mut rng);
            let spec = spec_of(&blank);
            problem(&blank, sim.as_ref(), &spec).kin_of(&x).unwrap()
        };
        let mut y = vec![0.0; n];
        assert!(sim.run(&truth, &kin, &mut y));
        let term: Vec<f64> = kin.iter().map(|k| f64::from(k.dx) * f64::from(k.dx).abs()).collect();
        let (lo, hi) = crate::numerics::stats::min_max(&y);
        let (t_lo, t_hi) = crate::numerics::stats::min_max(&term);
        let w = 0.05 * (hi - lo) / (t_hi - t_lo);
        let with_term: Vec<f64> = y.iter().zip(&term).map(|(y, t)| y + w * t).collect();
        let data = with_noise(x, &with_term, &mut rng);
        let spec = spec_of(&data);
        let prob = problem(&data, sim.as_ref(), &spec);
        let mut off = truth;
        off[1] *= 30.0;
        let reference = prob.refit(&[], &[], None, &off, 0).unwrap().0;
        let cands = vec![Candidate {
            effect: "rate_dependence",
            label: "term in |rate|·rate".into(),
            grid_name: None,
            grid: vec![0.0],
            build: Box::new(move |_| super::super::candidates::Piece {
                transform: None,
                terms: vec![Term::additive("c_rate", term.clone())],
            }),
            channel: None,
        }];
        let theta = starts(&prob, &cands, &reference, &[]).remove(0).expect("a start");
        assert!((theta[1] / truth[1]).ln().abs() < 0.9, "rate gain {} against {}", theta[1], truth[1]);
        let (_, terms_on) = cands[0].on_top(&reference, 0.0);
        let at = |theta: &[f64]| prob.refit(&[], &terms_on, None, theta, 0).unwrap().0.train_mse;
        let (joint, from_reference) = (at(&theta), at(&reference.theta));
        assert!(joint < 0.2 * from_reference, "{joint} against {from_reference}");
    }
}
