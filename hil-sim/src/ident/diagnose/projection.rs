//! The least squares inside every refit (variable projection): the terms' coefficients β
//! for fixed θ, on the training rows. Columns are scaled to unit norm and the normal
//! equations get a tiny ridge, so a column that duplicates another costs nothing instead of
//! breaking the solve.
//!
//! A refit's Levenberg–Marquardt solves it once per run of the base model (one per free
//! parameter for every Jacobian), and most columns (the additive terms) do not change
//! between those runs: a [`Projection`] gathers and scales them once, with their products,
//! and every solve computes only what depends on the base model's output. The arithmetic is
//! the same, in the same order, as solving from scratch ([`lsq`]).

use crate::numerics::lstsq::{self, dot};
use crate::numerics::spans::Spans;

/// A column on the rows, scaled to unit norm, and the norm it was divided by.
struct Scaled {
    values: Vec<f64>,
    norm: f64,
}

impl Scaled {
    /// `None` when the column is shorter than the last row.
    fn new(column: &[f64], rows: &Spans) -> Option<Self> {
        let v = rows.gather(column)?;
        let s = dot(&v, &v).sqrt();
        let norm = if s > 0.0 && s.is_finite() { s } else { 1.0 };
        Some(Self { values: v.into_iter().map(|x| x / norm).collect(), norm })
    }
}

/// `output − model` on `rows`; `None` when a row is past the end of either.
fn difference(output: &[f64], model: &[f64], rows: &Spans) -> Option<Vec<f64>> {
    rows.map2(output, model, |o, m| o - m)
}

/// A column of a [`Projection`].
enum Fixed {
    /// The same at every solve: gathered and scaled once.
    Prepared(Scaled),
    /// The same at every solve but shorter than the last row: no solve.
    Short,
    /// Given at every solve.
    Given,
}

/// Least squares on fixed rows whose fixed columns are prepared once.
pub struct Projection {
    rows: Spans,
    /// One entry per column.
    fixed: Vec<Fixed>,
    /// Products of the fixed columns' pairs (row-major, `k × k`; `None` where either varies).
    products: Vec<Option<f64>>,
    /// The columns whose coefficient is held ≥ 0 ([`Projection::at_least_zero`]).
    at_least_zero: Vec<bool>,
}

impl Projection {
    /// `columns`: `Some(values)` for a column that stays the same across solves (indexed by
    /// row, like the target), `None` for one given to every solve. A fixed column shorter
    /// than the last row is kept as missing: every solve then fails.
    pub fn new(columns: &[Option<&[f64]>], rows: &[usize]) -> Self {
        let rows = Spans::of(rows);
        let fixed: Vec<Fixed> = columns
            .iter()
            .map(|c| match c {
                Some(c) => Scaled::new(c, &rows).map_or(Fixed::Short, Fixed::Prepared),
                None => Fixed::Given,
            })
            .collect();
        let k = fixed.len();
        // The products of the prepared columns' pairs: their Gram matrix.
        let (at, cols): (Vec<usize>, Vec<&[f64]>) = fixed
            .iter()
            .enumerate()
            .filter_map(|(a, f)| match f {
                Fixed::Prepared(x) => Some((a, x.values.as_slice())),
                _ => None,
            })
            .unzip();
        let g = lstsq::gram(&cols);
        let mut products = vec![None; k * k];
        for (i, &a) in at.iter().enumerate() {
            for (j, &b) in at.iter().enumerate().skip(i) {
                products[a * k + b] = Some(g[(i, j)]);
            }
        }
        Self { rows, fixed, products, at_least_zero: Vec::new() }
    }

    /// The same, with the coefficients of the columns marked `true` held ≥ 0: a column whose
    /// coefficient comes out negative is left out and the rest solved again (until none
    /// is), so that its coefficient is 0. Exact for one held column (the play host's cubic,
    /// the only one today: a convex quadratic whose free minimum has it < 0 is least, over
    /// it ≥ 0, at 0); with several it is not the active-set answer of
    /// [`crate::numerics::nnls`], which a second held column should use instead.
    pub fn at_least_zero(self, marked: Vec<bool>) -> Self {
        Self { at_least_zero: marked, ..self }
    }

    /// Coefficients of the columns for the target `t` gathered on the rows, and the scaled
    /// solution's residual on the rows when `with_mse`. `varying`: the columns prepared as
    /// `None`, in their order. `None` when a column is missing or short, or the solve fails.
    fn solve_on_rows(&self, varying: &[&[f64]], t: Vec<f64>, with_mse: bool) -> Option<(Vec<f64>, f64)> {
        let n = self.rows.len().max(1) as f64;
        let k = self.fixed.len();
        if k == 0 {
            return Some((Vec::new(), dot(&t, &t) / n));
        }
        let mut given = varying.iter();
        let made: Vec<Option<Scaled>> = self
            .fixed
            .iter()
            .map(|f| match f {
                Fixed::Prepared(_) => Some(None),
                Fixed::Short => None,
                Fixed::Given => given.next().and_then(|c| Scaled::new(c, &self.rows)).map(Some),
            })
            .collect::<Option<_>>()?;
        let cols: Vec<&Scaled> = self
            .fixed
            .iter()
            .zip(&made)
            .filter_map(|(f, m)| match f {
                Fixed::Prepared(s) => Some(s),
                _ => m.as_ref(),
            })
            .collect();
        // The normal equations from column products (prepared where both are fixed), ridged;
        // the others and the right-hand side in one pass over the rows.
        let mut with_t: Vec<&[f64]> = cols.iter().map(|c| c.values.as_slice()).collect();
        with_t.push(&t);
        let pairs: Vec<(usize, usize)> = lstsq::upper_pairs(k)
            .filter(|&(a, b)| self.products[a * k + b].is_none())
            .chain((0..k).map(|a| (a, k)))
            .collect();
        let dots = lstsq::pair_dots(&with_t, &pairs);
        let mut g = nalgebra::DMatrix::<f64>::zeros(k, k);
        let mut rhs = nalgebra::DVector::<f64>::zeros(k);
        for a in 0..k {
            for b in a..k {
                if let Some(v) = self.products[a * k + b] {
                    g[(a, b)] = v;
                    g[(b, a)] = v;
                }
            }
        }
        for (&(a, b), v) in pairs.iter().zip(dots) {
            if b == k {
                rhs[a] = v;
            } else {
                g[(a, b)] = v;
                g[(b, a)] = v;
            }
        }
        for a in 0..k {
            g[(a, a)] += 1e-10;
        }
        let sol = self.solve_held(g, rhs)?;
        let coef: Vec<f64> = sol.iter().zip(&cols).map(|(v, c)| v / c.norm).collect();
        if coef.iter().any(|v| !v.is_finite()) {
            return None;
        }
        if !with_mse {
            return Some((coef, f64::NAN));
        }
        let mut r = t;
        for (c, w) in cols.iter().zip(sol.iter()) {
            for (r, c) in r.iter_mut().zip(&c.values) {
                *r -= w * c;
            }
        }
        Some((coef, dot(&r, &r) / n))
    }

    /// The ridged normal equations `g·s = rhs` solved, the coefficients held ≥ 0 left out
    /// (row and column of `g` made the identity's, `rhs` 0) while one is negative.
    fn solve_held(
        &self,
        mut g: nalgebra::DMatrix<f64>,
        mut rhs: nalgebra::DVector<f64>,
    ) -> Option<nalgebra::DVector<f64>> {
        if !self.at_least_zero.contains(&true) {
            return lstsq::solve_cholesky(g, &rhs, 1e-12);
        }
        loop {
            let sol = lstsq::solve_cholesky(g.clone(), &rhs, 1e-12)?;
            let negative: Vec<usize> =
                (0..sol.len()).filter(|&a| sol[a] < 0.0 && self.at_least_zero.get(a) == Some(&true)).collect();
            if negative.is_empty() {
                return Some(sol);
            }
            for a in negative {
                g.row_mut(a).fill(0.0);
                g.column_mut(a).fill(0.0);
                g[(a, a)] = 1.0;
                rhs[a] = 0.0;
            }
        }
    }

    /// Coefficients and the mean squared residual on the rows.
    pub fn fit(&self, varying: &[&[f64]], target: &[f64]) -> Option<(Vec<f64>, f64)> {
        self.solve_on_rows(varying, self.rows.gather(target)?, true)
    }

    /// Coefficients only (no residual), for `output − model` gathered on the rows from the
    /// two series (`model` at least as long as the last row).
    pub fn coefficients_for(&self, varying: &[&[f64]], output: &[f64], model: &[f64]) -> Option<Vec<f64>> {
        self.solve_on_rows(varying, difference(output, model, &self.rows)?, false).map(|(c, _)| c)
    }

    /// Coefficients and the mean squared residual for `output − model` on the rows.
    pub fn fit_for(&self, varying: &[&[f64]], output: &[f64], model: &[f64]) -> Option<(Vec<f64>, f64)> {
        self.solve_on_rows(varying, difference(output, model, &self.rows)?, true)
    }
}

/// Least squares of `target` on `columns` over `rows`: coefficients and the mean squared
/// residual on the rows (every column given, nothing prepared).
pub fn lsq(columns: &[&[f64]], target: &[f64], rows: &[usize]) -> Option<(Vec<f64>, f64)> {
    let none: Vec<Option<&[f64]>> = vec![None; columns.len()];
    Projection::new(&none, rows).fit(columns, target)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn columns(n: usize, seed: u64) -> Vec<Vec<f64>> {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        (0..4).map(|_| (0..n).map(|_| rng.random_range(-1.0..1.0)).collect()).collect()
    }

    #[test]
    fn prepared_columns_solve_bit_for_bit_as_from_scratch() {
        let n = 301;
        let cols = columns(n, 7);
        let y: Vec<f64> = (0..n).map(|i| (i as f64 * 0.1).sin() + 0.3 * cols[1][i]).collect();
        let rows: Vec<usize> = (0..n).filter(|i| i % 7 != 3).collect();
        let refs: Vec<&[f64]> = cols.iter().map(Vec::as_slice).collect();
        let scratch = lsq(&refs, &y, &rows).expect("solves");
        // Columns 0 and 2 prepared, 1 and 3 given at the solve.
        let prep = Projection::new(&[Some(refs[0]), None, Some(refs[2]), None], &rows);
        let (c, mse) = prep.fit(&[refs[1], refs[3]], &y).expect("solves");
        assert_eq!(c, scratch.0);
        assert_eq!(mse.to_bits(), scratch.1.to_bits());
        let m: Vec<f64> = (0..n).map(|i| 0.5 * y[i]).collect();
        let half: Vec<f64> = y.iter().zip(&m).map(|(y, m)| y - m).collect();
        let direct = prep.fit(&[refs[1], refs[3]], &half).expect("solves");
        assert_eq!(prep.fit_for(&[refs[1], refs[3]], &y, &m), Some(direct.clone()));
        assert_eq!(prep.coefficients_for(&[refs[1], refs[3]], &y, &m), Some(direct.0));
        assert!((c[1] - 0.3).abs() < 0.05, "{c:?}");
    }

    #[test]
    fn a_coefficient_held_at_least_zero_is_zero_where_it_would_be_negative() {
        let n = 200;
        let cols = columns(n, 9);
        let rows: Vec<usize> = (0..n).collect();
        let refs: Vec<&[f64]> = cols.iter().map(Vec::as_slice).collect();
        let y: Vec<f64> = (0..n).map(|i| 0.7 * cols[0][i] - 0.4 * cols[1][i] + 0.2 * cols[2][i]).collect();
        let free = lsq(&refs[..3], &y, &rows).expect("solves").0;
        assert!(free[1] < -0.3, "{free:?}");
        let held = Projection::new(&[Some(refs[0]), None, Some(refs[2])], &rows).at_least_zero(vec![false, true, true]);
        let (c, mse) = held.fit(&[refs[1]], &y).expect("solves");
        assert_eq!(c[1], 0.0);
        // The others are the least squares without it.
        let (without, mse_without) = lsq(&[refs[0], refs[2]], &y, &rows).expect("solves");
        assert!((c[0] - without[0]).abs() < 1e-9 && (c[2] - without[1]).abs() < 1e-9, "{c:?} {without:?}");
        assert!((mse - mse_without).abs() < 1e-12 && mse > 0.0);
        // A positive coefficient held ≥ 0 is the free one.
        let pos = Projection::new(&[Some(refs[0]), None, Some(refs[2])], &rows).at_least_zero(vec![true, false, true]);
        assert_eq!(pos.fit(&[refs[1]], &y).expect("solves").0, free);
    }

    #[test]
    fn a_missing_column_or_short_model_is_no_solution() {
        let cols = columns(50, 8);
        let rows: Vec<usize> = (0..50).collect();
        let prep = Projection::new(&[Some(&cols[0]), None], &rows);
        assert!(prep.fit(&[], &cols[1]).is_none());
        assert!(prep.coefficients_for(&[&cols[2]], &cols[1], &cols[3][..20]).is_none());
        assert!(lsq(&[], &cols[1], &rows).is_some_and(|(c, mse)| c.is_empty() && mse > 0.0));
        // A column or a target shorter than the last row is no solution, never a panic.
        assert!(Projection::new(&[Some(&cols[0][..20])], &rows).fit(&[], &cols[1]).is_none());
        assert!(lsq(&[&cols[0][..20]], &cols[1], &rows).is_none());
        assert!(lsq(&[&cols[0]], &cols[1][..20], &rows).is_none());
    }
}
