//! Linear least squares `y ≈ X·θ` for the lab's small fits (N ≤ 4 columns): the normal
//! equations `XᵀX·θ = Xᵀy`, solved by LU with partial pivoting (nalgebra).

use nalgebra::{DMatrix, DVector};

/// Solve the normal equations of a linear least-squares fit `y ≈ X·θ`; `None` when they
/// are singular or the solution is not finite.
pub fn least_squares<const N: usize>(rows: &[[f64; N]], y: &[f64]) -> Option<[f64; N]> {
    let mut a = DMatrix::<f64>::zeros(N, N);
    let mut b = DVector::<f64>::zeros(N);
    for (x, yv) in rows.iter().zip(y) {
        for i in 0..N {
            b[i] += x[i] * yv;
            for j in 0..N {
                a[(i, j)] += x[i] * x[j];
            }
        }
    }
    let th = a.lu().solve(&b)?;
    let x: [f64; N] = std::array::from_fn(|i| th[i]);
    x.iter().all(|v| v.is_finite()).then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn least_squares_recovers_a_line() {
        let rows: Vec<[f64; 2]> = (0..10).map(|k| [1.0, k as f64]).collect();
        let y: Vec<f64> = (0..10).map(|k| 2.0 + 0.5 * k as f64).collect();
        let th = least_squares(&rows, &y).unwrap();
        assert!((th[0] - 2.0).abs() < 1e-9 && (th[1] - 0.5).abs() < 1e-9);
        assert!(least_squares(&[[0.0, 0.0]], &[1.0]).is_none());
    }
}
