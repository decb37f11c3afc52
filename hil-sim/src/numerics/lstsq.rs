//! Linear least squares on the normal equations of small problems (a few dozen columns at
//! most): accumulate `AᵀA`, `Aᵀb` row by row without an m×n matrix (or, for columns already
//! in memory, from their products: [`gram`]), then solve by SVD with a
//! relative cut-off (a column the data does not excite gets a zero coefficient instead of a
//! blow-up), or by Cholesky with a ridge. The sign-constrained variant is [`super::nnls`].

use nalgebra::{DMatrix, DVector};

/// `Σ aᵢ·bᵢ` in eight independent partial sums (vectorised, and the same on every machine:
/// the order of the additions is fixed).
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    let (ca, cb) = (a.chunks_exact(8), b.chunks_exact(8));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    finished(partial_sums([0.0; 8], a, b), ra, rb)
}

/// The eight partial sums `acc` added in a fixed order, then the products of the rows past
/// the whole chunks (`ra`, `rb`) one by one.
#[inline(always)]
fn finished(acc: [f64; 8], ra: &[f64], rb: &[f64]) -> f64 {
    let mut s = ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7]));
    for (x, y) in ra.iter().zip(rb) {
        s += x * y;
    }
    s
}

/// `acc` with the products of `a` and `b` added, eight rows at a time (row `8i + k` into
/// `acc[k]`), over the whole chunks of eight of the shorter.
#[inline(always)]
fn partial_sums(mut acc: [f64; 8], a: &[f64], b: &[f64]) -> [f64; 8] {
    for (x, y) in a.chunks_exact(8).zip(b.chunks_exact(8)) {
        for k in 0..8 {
            acc[k] += x[k] * y[k];
        }
    }
    acc
}

/// The pairs `(a, b)` with `a ≤ b < k`: the upper triangle of a `k × k` matrix, row by row.
pub fn upper_pairs(k: usize) -> impl Iterator<Item = (usize, usize)> {
    (0..k).flat_map(move |a| (a..k).map(move |b| (a, b)))
}

/// `AᵀA` of the columns `cols` (equal lengths) by their products ([`dot`]), each pair once.
pub fn gram(cols: &[&[f64]]) -> DMatrix<f64> {
    let k = cols.len();
    let pairs: Vec<(usize, usize)> = upper_pairs(k).collect();
    let mut g = DMatrix::<f64>::zeros(k, k);
    for (&(a, b), v) in pairs.iter().zip(pair_dots(cols, &pairs)) {
        g[(a, b)] = v;
        g[(b, a)] = v;
    }
    g
}

/// Rows per block of [`pair_dots`]: a column's block is 16 KiB, so the blocks of a dozen
/// columns stay in the core's second-level cache while every pair is summed.
const BLOCK_ROWS: usize = 2048;

/// [`dot`] of `cols[a]` and `cols[b]` for each `(a, b)` of `pairs`, the same sums to the
/// bit: each pair's eight partial sums run over the rows in the same order, but block by
/// block of [`BLOCK_ROWS`], so that each column is read from memory once rather than once
/// per pair it is in (tens of thousands of rows: the dot products of a Gram matrix were
/// bound by memory, not arithmetic). Columns of unequal lengths are summed pair by pair.
pub fn pair_dots(cols: &[&[f64]], pairs: &[(usize, usize)]) -> Vec<f64> {
    let n = cols.first().map_or(0, |c| c.len());
    let valid = pairs.iter().all(|&(a, b)| a < cols.len() && b < cols.len());
    if !valid || cols.iter().any(|c| c.len() != n) {
        // A pair past the columns is NaN.
        let one = |&(a, b): &(usize, usize)| cols.get(a).zip(cols.get(b)).map_or(f64::NAN, |(x, y)| dot(x, y));
        return pairs.iter().map(one).collect();
    }
    let whole = n - n % 8;
    let mut acc = vec![[0.0f64; 8]; pairs.len()];
    let mut lo = 0;
    while lo < whole {
        let hi = (lo + BLOCK_ROWS).min(whole);
        for (acc, &(a, b)) in acc.iter_mut().zip(pairs) {
            *acc = partial_sums(*acc, &cols[a][lo..hi], &cols[b][lo..hi]);
        }
        lo = hi;
    }
    acc.iter().zip(pairs).map(|(acc, &(a, b))| finished(*acc, &cols[a][whole..], &cols[b][whole..])).collect()
}

/// Add one row `a` with target `b` to the lower triangle of `gram` and to `atb`.
pub fn accumulate(gram: &mut DMatrix<f64>, atb: &mut DVector<f64>, a: &[f64], b: f64) {
    let n = atb.len();
    let a = &a[..n];
    for (t, ar) in atb.iter_mut().zip(a) {
        *t += ar * b;
    }
    // Column by column (contiguous in the column-major storage); every entry gets the same
    // one product per row as entry by entry would.
    for (c, &ac) in a.iter().enumerate() {
        let mut col = gram.column_mut(c);
        let Some(col) = col.as_mut_slice().get_mut(c..n) else { continue };
        for (g, ar) in col.iter_mut().zip(&a[c..]) {
            *g += ar * ac;
        }
    }
}

/// Copy the lower triangle of `gram` to the upper one.
pub fn symmetrize(gram: &mut DMatrix<f64>) {
    for r in 0..gram.nrows() {
        for c in 0..r {
            gram[(c, r)] = gram[(r, c)];
        }
    }
}

/// Normal equations `AᵀA`, `Aᵀb` of the columns `cols` at the rows `rows` (`b = y`).
pub fn normal_equations(cols: &[Vec<f64>], y: &[f64], rows: &[usize]) -> (DMatrix<f64>, DVector<f64>) {
    // The few-column systems of the projected fits (run once per model evaluation) on the
    // stack: the same sums in the same order, so the same numbers.
    match cols.len() {
        1 => return normal_equations_n::<1>(cols, y, rows),
        2 => return normal_equations_n::<2>(cols, y, rows),
        3 => return normal_equations_n::<3>(cols, y, rows),
        4 => return normal_equations_n::<4>(cols, y, rows),
        _ => {}
    }
    let n = cols.len();
    let mut gram = DMatrix::<f64>::zeros(n, n);
    let mut atb = DVector::<f64>::zeros(n);
    let mut a = vec![0.0; n];
    for &i in rows {
        let (Some(&yi), true) = (y.get(i), cols.iter().all(|c| i < c.len())) else { continue };
        for (v, c) in a.iter_mut().zip(cols) {
            *v = c.get(i).copied().unwrap_or(0.0);
        }
        accumulate(&mut gram, &mut atb, &a, yi);
    }
    symmetrize(&mut gram);
    (gram, atb)
}

/// [`normal_equations`] for `N` columns (`cols.len() == N`).
fn normal_equations_n<const N: usize>(cols: &[Vec<f64>], y: &[f64], rows: &[usize]) -> (DMatrix<f64>, DVector<f64>) {
    let c: [&[f64]; N] = std::array::from_fn(|k| cols.get(k).map_or(&[][..], |v| v.as_slice()));
    let len = c.iter().map(|v| v.len()).min().unwrap_or(0);
    let mut g = [[0.0f64; N]; N];
    let mut atb = [0.0f64; N];
    for &i in rows {
        let (Some(&yi), true) = (y.get(i), i < len) else { continue };
        let a: [f64; N] = std::array::from_fn(|k| c[k][i]);
        for r in 0..N {
            atb[r] += a[r] * yi;
            for k in 0..=r {
                g[r][k] += a[r] * a[k];
            }
        }
    }
    let gram = DMatrix::from_fn(N, N, |r, k| if k <= r { g[r][k] } else { g[k][r] });
    (gram, DVector::from_row_slice(&atb))
}

/// Fit `y ≈ X·θ` for rows of `N` columns (the lab's small fits): the normal equations
/// solved by LU with partial pivoting; `None` when they are singular or the solution is
/// not finite.
pub fn fit_rows<const N: usize>(rows: &[[f64; N]], y: &[f64]) -> Option<[f64; N]> {
    let mut gram = DMatrix::<f64>::zeros(N, N);
    let mut atb = DVector::<f64>::zeros(N);
    for (x, yv) in rows.iter().zip(y) {
        accumulate(&mut gram, &mut atb, x, *yv);
    }
    symmetrize(&mut gram);
    let th = gram.lu().solve(&atb)?;
    let x: [f64; N] = std::array::from_fn(|i| th[i]);
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// Solve `g·θ = b` by SVD, singular values below `rcond` × the largest cut off.
pub fn solve_svd(g: DMatrix<f64>, b: &DVector<f64>, rcond: f64) -> Option<DVector<f64>> {
    let svd = g.svd(true, true);
    let cut = rcond * svd.singular_values.max();
    svd.solve(b, cut).ok()
}

/// [`solve_svd`] on the normal equations with every column scaled to unit norm first (so
/// the cut-off is relative per column, whatever the columns' units); the solution in the
/// original scaling.
pub fn solve_scaled(mut gram: DMatrix<f64>, mut atb: DVector<f64>, rcond: f64) -> Option<DVector<f64>> {
    let n = atb.len();
    let scale: Vec<f64> = (0..n).map(|c| gram[(c, c)].sqrt()).map(|v| if v > 0.0 { 1.0 / v } else { 0.0 }).collect();
    for r in 0..n {
        atb[r] *= scale[r];
        for c in 0..n {
            gram[(r, c)] *= scale[r] * scale[c];
        }
    }
    let sol = solve_svd(gram, &atb, rcond)?;
    Some(DVector::from_fn(n, |c, _| sol[c] * scale.get(c).copied().unwrap_or(0.0)))
}

/// Solve `g·θ = b` by Cholesky (`g` symmetric positive definite, e.g. normal equations
/// with a ridge on the diagonal); SVD with an absolute cut-off `svd_eps` when Cholesky fails.
pub fn solve_cholesky(g: DMatrix<f64>, b: &DVector<f64>, svd_eps: f64) -> Option<DVector<f64>> {
    g.clone().cholesky().map(|ch| ch.solve(b)).or_else(|| g.svd(true, true).solve(b, svd_eps).ok())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dots_in_blocks_are_the_dots_to_the_bit() {
        let col = |n: usize, f: f64| -> Vec<f64> { (0..n).map(|i| (i as f64 * f).sin() * (1.0 + i as f64)).collect() };
        for n in [0, 5, 8, 13, BLOCK_ROWS, BLOCK_ROWS + 3, 3 * BLOCK_ROWS + 17] {
            let cols: Vec<Vec<f64>> = (0..4).map(|k| col(n, 0.1 + 0.37 * k as f64)).collect();
            let refs: Vec<&[f64]> = cols.iter().map(Vec::as_slice).collect();
            let pairs = [(0, 0), (0, 3), (2, 1), (3, 3), (1, 2)];
            let got: Vec<u64> = pair_dots(&refs, &pairs).iter().map(|v| v.to_bits()).collect();
            let want: Vec<u64> = pairs.iter().map(|&(a, b)| dot(refs[a], refs[b]).to_bits()).collect();
            assert_eq!(got, want, "{n} rows");
            let g = gram(&refs);
            assert!(pairs.iter().all(|&(a, b)| g[(a, b)] == dot(refs[a], refs[b]) && g[(b, a)] == g[(a, b)]));
        }
        // Unequal lengths: pair by pair, as `dot` pairs them; a pair past the columns is NaN.
        let (a, b) = (col(3000, 0.2), col(2100, 0.3));
        let got = pair_dots(&[&a, &b], &[(0, 1), (1, 1), (0, 2)]);
        assert_eq!(got[..2], [dot(&a, &b), dot(&b, &b)]);
        assert!(got[2].is_nan());
    }

    #[test]
    fn fit_rows_recovers_a_line() {
        let rows: Vec<[f64; 2]> = (0..10).map(|k| [1.0, k as f64]).collect();
        let y: Vec<f64> = (0..10).map(|k| 2.0 + 0.5 * k as f64).collect();
        let th = fit_rows(&rows, &y).unwrap();
        assert!((th[0] - 2.0).abs() < 1e-9 && (th[1] - 0.5).abs() < 1e-9);
        assert!(fit_rows(&[[0.0, 0.0]], &[1.0]).is_none());
    }

    #[test]
    fn recovers_a_line_and_zeroes_an_unexcited_column() {
        let rows: Vec<usize> = (0..50).collect();
        let x: Vec<f64> = rows.iter().map(|&i| i as f64 / 10.0).collect();
        let cols = vec![x.clone(), vec![1.0; 50], vec![0.0; 50]];
        let y: Vec<f64> = x.iter().map(|v| 3.0 * v - 2.0).collect();
        let (g, b) = normal_equations(&cols, &y, &rows);
        let th = solve_scaled(g.clone(), b.clone(), 1e-13).unwrap();
        assert!((th[0] - 3.0).abs() < 1e-9 && (th[1] + 2.0).abs() < 1e-9 && th[2] == 0.0, "{th:?}");
        let ridge = DMatrix::from_fn(3, 3, |r, c| g[(r, c)] + if r == c { 1e-9 } else { 0.0 });
        let th = solve_cholesky(ridge, &b, 1e-12).unwrap();
        assert!((th[0] - 3.0).abs() < 1e-6, "{th:?}");
    }
}
