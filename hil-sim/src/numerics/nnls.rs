//! Least squares with sign constraints on some coefficients (Lawson & Hanson 1974, the
//! active-set NNLS), on the normal equations of a small problem (≤ a few dozen columns).
//!
//! No maintained Rust crate solves this on nalgebra matrices (the `nnls` crate works on
//! ndarray and has no free, unconstrained columns), and the problems here have at most a
//! dozen columns, so the active-set loop is written out; each subproblem is solved by SVD
//! with a relative cut-off ([`super::lstsq::solve_svd`]).

use nalgebra::{DMatrix, DVector};

pub use super::lstsq::normal_equations;

/// Unconstrained solution restricted to the columns in `set` (others 0).
fn solve_subset(gram: &DMatrix<f64>, atb: &DVector<f64>, set: &[usize]) -> Option<DVector<f64>> {
    let k = set.len();
    let mut out = DVector::zeros(atb.len());
    if k == 0 {
        return Some(out);
    }
    let g = DMatrix::from_fn(k, k, |r, c| gram[(set[r], set[c])]);
    let b = DVector::from_fn(k, |r, _| atb[set[r]]);
    let z = super::lstsq::solve_svd(g, &b, 1e-12)?;
    for (r, &j) in set.iter().enumerate() {
        out[j] = z[r];
    }
    Some(out)
}

/// Minimise `‖Aθ − b‖²` given `AᵀA` and `Aᵀb`, with `θⱼ ≥ 0` where `nonneg[j]`.
/// `None` when a subproblem cannot be solved (non-finite data).
pub fn solve(gram: &DMatrix<f64>, atb: &DVector<f64>, nonneg: &[bool]) -> Option<DVector<f64>> {
    let n = atb.len();
    if gram.nrows() != n || gram.ncols() != n || nonneg.len() != n {
        return None;
    }
    // Scale the columns to unit norm (a positive scaling keeps the sign constraints).
    let s: Vec<f64> = (0..n).map(|j| gram[(j, j)].sqrt()).map(|v| if v > 0.0 { 1.0 / v } else { 0.0 }).collect();
    let g = DMatrix::from_fn(n, n, |r, c| gram[(r, c)] * s[r] * s[c]);
    let b = DVector::from_fn(n, |r, _| atb[r] * s[r]);
    let dead = |j: usize| s[j] == 0.0;
    let mut passive: Vec<usize> = (0..n).filter(|&j| !nonneg[j] && !dead(j)).collect();
    let mut x = solve_subset(&g, &b, &passive)?;
    let tol = 1e-12 * b.amax().max(1e-300);
    for _ in 0..3 * n + 10 {
        let w = &b - &g * &x;
        let pick = (0..n)
            .filter(|&j| nonneg[j] && !dead(j) && !passive.contains(&j))
            .filter(|&j| w[j] > tol)
            .max_by(|&a, &c| w[a].total_cmp(&w[c]));
        let Some(j) = pick else { break };
        passive.push(j);
        for _ in 0..3 * n + 10 {
            let z = solve_subset(&g, &b, &passive)?;
            let bad: Vec<usize> = passive.iter().copied().filter(|&j| nonneg[j] && z[j] <= 0.0).collect();
            if bad.is_empty() {
                x = z;
                break;
            }
            let alpha = bad
                .iter()
                .map(|&j| {
                    let d = x[j] - z[j];
                    if d > 0.0 {
                        x[j] / d
                    } else {
                        0.0
                    }
                })
                .fold(1.0f64, f64::min)
                .clamp(0.0, 1.0);
            x += (z - &x) * alpha;
            passive.retain(|&j| !(nonneg[j] && x[j] <= 1e-15));
            for j in 0..n {
                if !passive.contains(&j) {
                    x[j] = 0.0;
                }
            }
        }
    }
    if !x.iter().all(|v| v.is_finite()) {
        return None;
    }
    Some(DVector::from_fn(n, |j, _| x[j] * s[j]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_unconstrained_when_inactive_and_clips_when_active() {
        // y = 2·a − 3·b + 1 on a grid.
        let m = 200;
        let a: Vec<f64> = (0..m).map(|i| (i as f64 * 0.1).sin()).collect();
        let b: Vec<f64> = (0..m).map(|i| (i as f64 * 0.37).cos()).collect();
        let one = vec![1.0; m];
        let y: Vec<f64> = (0..m).map(|i| 2.0 * a[i] - 3.0 * b[i] + 1.0).collect();
        let rows: Vec<usize> = (0..m).collect();
        let (g, r) = normal_equations(&[a.clone(), b.clone(), one.clone()], &y, &rows);
        let free = solve(&g, &r, &[false, false, false]).unwrap();
        assert!((free[0] - 2.0).abs() < 1e-9 && (free[1] + 3.0).abs() < 1e-9 && (free[2] - 1.0).abs() < 1e-9);
        let pos = solve(&g, &r, &[true, false, false]).unwrap();
        assert!((pos[0] - 2.0).abs() < 1e-9, "inactive constraint changes nothing: {pos}");
        // b ≥ 0 is active: its coefficient is 0 and the rest is the LS fit without it.
        let clipped = solve(&g, &r, &[true, true, false]).unwrap();
        assert_eq!(clipped[1], 0.0);
        let (g2, r2) = normal_equations(&[a, one], &y, &rows);
        let sub = solve(&g2, &r2, &[false, false]).unwrap();
        assert!((clipped[0] - sub[0]).abs() < 1e-9 && (clipped[2] - sub[1]).abs() < 1e-9);
    }
}
