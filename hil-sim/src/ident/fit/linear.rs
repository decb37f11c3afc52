//! Closed-form least squares for the models that are linear in their parameters (today the
//! algebraic model, seed 000 eq. 14, and the Bingham model with its command polynomials,
//! seed 003 eq. 12–14; each declares its regressors in its host file).
//!
//! The regressors are evaluated on the same f32 kinematics the core sees; a unit test
//! checks them against the core's own output so the two cannot drift apart.

use model_core::Kin;
use nalgebra::{DMatrix, DVector};

use crate::models::MAX_REGRESSORS;
use crate::numerics::lstsq;

/// Regressor row of model `id` at one sample (`None` for a model that is not linear);
/// each model writes its own in its host file ([`crate::models::HostModel::regressors`]).
pub fn regressors(id: &str, k: &Kin) -> Option<Vec<f64>> {
    crate::models::host(id)?.regressors(k)
}

/// Least-squares solution over the rows `rows` of the free columns `free`; fixed
/// parameters keep their value in `p` (their contribution is subtracted first).
///
/// One pass accumulates the normal equations `AᵀA·θ = Aᵀb` (at most 10 columns, so this
/// costs a few multiply-adds per sample and no m×n matrix). The columns are scaled to unit
/// norm and the small system is solved by SVD with a relative cut-off, so a column the data
/// does not excite gets a zero coefficient instead of a blow-up. `None` for a model that is
/// not linear.
pub fn solve(id: &str, kin: &[Kin], y: &[f64], rows: &[usize], free: &[usize], p: &[f64]) -> Option<Vec<f64>> {
    let host = crate::models::host(id)?;
    let n = free.len();
    let mut gram = DMatrix::<f64>::zeros(n, n);
    let mut atb = DVector::<f64>::zeros(n);
    let mut phi = [0.0; MAX_REGRESSORS];
    let mut is_free = [false; MAX_REGRESSORS];
    for &j in free {
        *is_free.get_mut(j)? = true;
    }
    let mut a = [0.0; MAX_REGRESSORS];
    for &i in rows {
        let len = host.regressors_into(kin.get(i)?, &mut phi)?;
        let fixed: f64 = (0..len).filter(|&j| !is_free[j]).map(|j| phi[j] * p.get(j).copied().unwrap_or(0.0)).sum();
        let b = y.get(i)? - fixed;
        for (c, &j) in free.iter().enumerate() {
            a[c] = *phi.get(j)?;
        }
        lstsq::accumulate(&mut gram, &mut atb, &a[..n], b);
    }
    lstsq::symmetrize(&mut gram);
    let sol = lstsq::solve_scaled(gram, atb, 1e-13)?;
    let mut out = p.to_vec();
    for (c, &j) in free.iter().enumerate() {
        *out.get_mut(j)? = sol[c];
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ident::fit::simulate::simulator;

    fn kin(n: usize) -> Vec<Kin> {
        (0..n)
            .map(|i| {
                let t = i as f32 * 1e-3;
                Kin::new((9.0 * t).sin(), 9.0 * (9.0 * t).cos(), 0.0, 1.0 + (2.0 * t).sin())
            })
            .collect()
    }

    #[test]
    fn regressors_reproduce_the_core() {
        let k = kin(500);
        for (id, p) in [
            ("algebraic", vec![2.0, 0.3, -1.5, 0.7]),
            ("bingham", vec![50.0, 20.0, -3.0, 0.5, 1.2, 0.4, -0.1, 0.02, 0.001, 5.0]),
        ] {
            let sim = simulator(id, 1e-3).unwrap();
            let mut out = vec![0.0; k.len()];
            assert!(sim.run(&p, &k, &mut out));
            for (kk, o) in k.iter().zip(&out) {
                let lin: f64 = regressors(id, kk).unwrap().iter().zip(&p).map(|(a, b)| a * b).sum();
                assert!((lin - o).abs() <= 1e-4 * (1.0 + o.abs()), "{id}: {lin} vs {o}");
            }
        }
        assert!(regressors("bouc_wen", &Kin::default()).is_none());
    }

    #[test]
    fn recovers_exact_parameters_and_respects_fixed_ones() {
        let k = kin(2000);
        let truth = vec![2.0, 0.3, -1.5, 0.7];
        let y: Vec<f64> = k
            .iter()
            .map(|kk| regressors("algebraic", kk).unwrap().iter().zip(&truth).map(|(a, b)| a * b).sum())
            .collect();
        let rows: Vec<usize> = (0..k.len()).collect();
        let got = solve("algebraic", &k, &y, &rows, &[0, 1, 2, 3], &[0.0; 4]).unwrap();
        for (g, t) in got.iter().zip(&truth) {
            assert!((g - t).abs() < 1e-9, "{got:?}");
        }
        // α held at its true value, the rest solved.
        let got = solve("algebraic", &k, &y, &rows, &[0, 1, 3], &[0.0, 0.0, -1.5, 0.0]).unwrap();
        assert!((got[0] - 2.0).abs() < 1e-9 && got[2] == -1.5);
    }
}
