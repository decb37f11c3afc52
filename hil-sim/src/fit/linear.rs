//! Closed-form least squares for the models that are linear in their parameters: the
//! algebraic model (seed 000 eq. 14) and the Bingham model with its command polynomials
//! (seed 003 eq. 12–14).
//!
//! The regressors are evaluated on the same f32 kinematics the core sees; a unit test
//! checks them against the core's own output so the two cannot drift apart.

use model_core::Kin;
use nalgebra::{DMatrix, DVector};

/// Regressor row of model `id` at one sample (`None` for a model that is not linear).
pub fn regressors(id: &str, k: &Kin) -> Option<Vec<f64>> {
    let (x, dx, u) = (f64::from(k.x), f64::from(k.dx), f64::from(k.u));
    let sgn = |v: f64| {
        if v > 0.0 {
            1.0
        } else if v < 0.0 {
            -1.0
        } else {
            0.0
        }
    };
    Some(match id {
        // T = k·B + c·Ḃ + α·|B|·B³ + T₀
        "algebraic" => vec![x, dx, x.abs() * x.powi(3), 1.0],
        // F = (fc0 + fc1·u + fc2·u² + fc3·u³)·sgn(ẋ) + (c0_0 + … + c0_4·u⁴)·ẋ + f0
        "bingham" => {
            let s = sgn(dx);
            vec![s, s * u, s * u * u, s * u.powi(3), dx, dx * u, dx * u * u, dx * u.powi(3), dx * u.powi(4), 1.0]
        }
        _ => return None,
    })
}

/// Least-squares solution over the rows `rows` of the free columns `free`; fixed
/// parameters keep their value in `p` (their contribution is subtracted first).
/// Columns are scaled to unit norm and solved by SVD, so a column the data does not excite
/// gets a zero coefficient instead of a blow-up. `None` for a model that is not linear.
pub fn solve(id: &str, kin: &[Kin], y: &[f64], rows: &[usize], free: &[usize], p: &[f64]) -> Option<Vec<f64>> {
    let m = rows.len();
    let n = free.len();
    let mut a = DMatrix::<f64>::zeros(m, n);
    let mut b = DVector::<f64>::zeros(m);
    for (r, &i) in rows.iter().enumerate() {
        let phi = regressors(id, kin.get(i)?)?;
        let fixed: f64 =
            phi.iter().zip(p).enumerate().filter(|(j, _)| !free.contains(j)).map(|(_, (f, v))| f * v).sum();
        b[r] = y.get(i)? - fixed;
        for (c, &j) in free.iter().enumerate() {
            a[(r, c)] = *phi.get(j)?;
        }
    }
    let norms: Vec<f64> = (0..n).map(|c| a.column(c).norm()).collect();
    for (c, nrm) in norms.iter().enumerate() {
        if *nrm > 0.0 {
            a.column_mut(c).scale_mut(1.0 / nrm);
        }
    }
    let svd = a.svd(true, true);
    let sol = svd.solve(&b, 1e-12).ok()?;
    let mut out = p.to_vec();
    for (c, &j) in free.iter().enumerate() {
        let nrm = norms.get(c).copied().unwrap_or(0.0);
        *out.get_mut(j)? = if nrm > 0.0 { sol[c] / nrm } else { 0.0 };
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::simulate::simulator;

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
