//! A tall least-squares step reduced to a square one, for Levenberg–Marquardt on long
//! recordings.
//!
//! The `levenberg-marquardt` crate factors the Jacobian it is given (a pivoted Householder
//! QR, column by column): for a network trained on thousands of rows that factorisation, not
//! the network, is most of the fit. Every quantity the solver computes (the scaled gradient
//! `Jᵀr`, the column norms, `‖J·p‖`, the step) depends on `J` and `r` only through `JᵀJ`,
//! `Jᵀr` and `‖r‖`, so the problem with `m` rows can be handed to it as one with `n + 1`:
//! the residual vector `‖r‖·e₁` and the matrix `A` (`(n + 1) × n`) of the Cholesky factor of
//! `[r J]ᵀ[r J]` without its first column, which has `AᵀA = JᵀJ`, `Aᵀ(‖r‖·e₁) = Jᵀr`. The
//! Gram matrix is column dot products in a fixed order (vectorised, machine-independent, so
//! a fit gives the same numbers everywhere); a direction the columns do not excite (a zero
//! column, a numerically dependent one) gets a zero row.

use nalgebra::{DMatrix, DVector};

/// Relative pivot below which a direction counts as dependent on the earlier ones.
const DEPENDENT: f64 = 1e-13;

/// `A` for Jacobian `j` (`m × n`) and residuals `r` (`m`): `(n + 1) × n` with `AᵀA = JᵀJ`
/// and `A`'s first row `rᵀJ / ‖r‖` (so `Aᵀ(‖r‖·e₁) = Jᵀr`); rows of `A` below a dependent
/// pivot are zero.
pub fn reduced(j: &DMatrix<f64>, r: &[f64]) -> DMatrix<f64> {
    let (rows, n) = j.shape();
    // J is stored column by column.
    let cols: Vec<&[f64]> = (0..n).map(|c| &j.as_slice()[c * rows..(c + 1) * rows]).collect();
    reduced_columns(&cols, r)
}

/// [`reduced`] for the Jacobian's columns as they were computed (no `m × n` matrix made).
pub fn reduced_columns(j: &[&[f64]], r: &[f64]) -> DMatrix<f64> {
    let n = j.len();
    let cols: Vec<&[f64]> = std::iter::once(r).chain(j.iter().copied()).collect();
    let g = super::lstsq::gram(&cols);
    let mut u = DMatrix::<f64>::zeros(n + 1, n + 1);
    for k in 0..=n {
        let d = g[(k, k)] - (0..k).map(|i| u[(i, k)] * u[(i, k)]).sum::<f64>();
        // Also a NaN pivot: the row stays zero.
        let independent = d > DEPENDENT * g[(k, k)] && d.is_finite();
        if !independent {
            continue;
        }
        let piv = d.sqrt();
        u[(k, k)] = piv;
        for c in k + 1..=n {
            u[(k, c)] = (g[(k, c)] - (0..k).map(|i| u[(i, k)] * u[(i, c)]).sum::<f64>()) / piv;
        }
    }
    u.columns(1, n).into_owned()
}

/// The residual vector that goes with [`reduced`]: `‖r‖·e₁` (`n + 1` entries).
pub fn reduced_residuals(r: &[f64], n: usize) -> DVector<f64> {
    let mut v = DVector::zeros(n + 1);
    v[0] = r.iter().map(|x| x * x).sum::<f64>().sqrt();
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_the_normal_equations() {
        let (m, n) = (200, 5);
        let j = DMatrix::from_fn(m, n, |i, c| ((i * (c + 3)) as f64 * 0.37).sin() + if c == 2 { 0.0 } else { 0.1 });
        let mut j = j;
        j.column_mut(4).fill(0.0); // a frozen direction
        let r: Vec<f64> = (0..m).map(|i| (i as f64 * 0.11).cos()).collect();
        let a = reduced(&j, &r);
        let b = reduced_residuals(&r, n);
        let rv = DVector::from_vec(r.clone());
        assert!(((a.transpose() * &a) - j.transpose() * &j).amax() < 1e-9);
        assert!(((a.transpose() * &b) - j.transpose() * &rv).amax() < 1e-9);
        assert!((b.norm() - rv.norm()).abs() < 1e-12);
        // The same matrix from the columns as computed, to the bit.
        let cols: Vec<Vec<f64>> = (0..n).map(|c| j.column(c).iter().copied().collect()).collect();
        let cols: Vec<&[f64]> = cols.iter().map(Vec::as_slice).collect();
        assert_eq!(reduced_columns(&cols, &r), a);
    }
}
