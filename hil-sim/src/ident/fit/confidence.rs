//! Which fitted parameters the data cannot tell from zero (issue 16): the linearised 95 %
//! confidence interval of each free parameter, `θ̂ ± 1.96·σ·√((JᵀJ)⁻¹)ⱼⱼ`, from a
//! forward-difference Jacobian of the scaled training residuals through the f32 core, with
//! `σ²` inflated by `(1 + ρ)/(1 − ρ)` for the residuals' lag-1 autocorrelation `ρ` (neighbouring
//! samples of a recording are not independent).

use nalgebra::DMatrix;

use super::objective::Objective;

/// A parameter whose interval spans zero: (index, value, half-width of the 95 % interval).
pub type Unresolved = (usize, f64, f64);

/// The free parameters of `p` (a full vector of `obj`'s spec) whose interval spans zero.
pub fn spanning_zero(obj: &Objective<'_>, p: &[f64]) -> Vec<Unresolved> {
    let Some(r0) = obj.residuals(p) else { return Vec::new() };
    let (n, k) = (r0.len(), obj.free.len());
    if k == 0 || n <= k + 1 {
        return Vec::new();
    }
    let mut jac = DMatrix::<f64>::zeros(n, k);
    for (c, &j) in obj.free.iter().enumerate() {
        let Some(spec) = obj.spec.params.get(j) else { return Vec::new() };
        let v = p.get(j).copied().unwrap_or(0.0);
        let h = 1e-4 * v.abs().max(1e-3 * (spec.hi - spec.lo).abs()).max(1e-12);
        let mut q = p.to_vec();
        q[j] = v + h;
        let Some(r) = obj.residuals(&q) else { continue };
        for (i, (a, b)) in r.iter().zip(&r0).enumerate() {
            jac[(i, c)] = (a - b) / h;
        }
    }
    let ss: f64 = r0.iter().map(|r| r * r).sum();
    let rho = {
        let num: f64 = r0.windows(2).map(|w| w[0] * w[1]).sum();
        (num / ss.max(1e-300)).clamp(0.0, 0.999)
    };
    let sigma2 = ss / (n - k) as f64 * (1.0 + rho) / (1.0 - rho);
    let Some(inv) = (jac.transpose() * &jac).try_inverse() else { return Vec::new() };
    obj.free
        .iter()
        .enumerate()
        .filter_map(|(c, &j)| {
            let var = inv[(c, c)] * sigma2;
            let half = 1.96 * var.max(0.0).sqrt();
            let v = p.get(j).copied()?;
            (var.is_finite() && v.abs() < half).then_some((j, v, half))
        })
        .collect()
}

/// The warning naming them.
pub fn warning(names: &[&str], unresolved: &[Unresolved]) -> Option<String> {
    if unresolved.is_empty() {
        return None;
    }
    let list: Vec<String> = unresolved
        .iter()
        .map(|&(j, v, h)| format!("{} = {v:.4} ± {h:.4}", names.get(j).copied().unwrap_or("?")))
        .collect();
    Some(format!(
        "the data cannot tell {} from zero (95 % confidence interval spans zero); treat {} as undetermined",
        list.join(", "),
        if unresolved.len() == 1 { "it" } else { "them" }
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ident::fit::simulate::{kinematics, simulator};
    use crate::io::recording::{Channels, Column, Recording};
    use crate::models::RateSpec;

    #[test]
    fn terms_that_are_zero_in_truth_are_flagged_and_strong_ones_are_not() {
        // T = k·B + c·Ḃ + α·|B|·B³ + T₀ with α = T₀ = 0, plus noise.
        let (n, dt) = (4000, 1e-3);
        let t: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
        let b: Vec<f64> = t.iter().map(|t| (6.0 * t).sin() + 0.3 * (23.0 * t).sin()).collect();
        let samples: Vec<model_core::Sample> = b.iter().map(|v| model_core::Sample::new(*v as f32)).collect();
        let kin = kinematics(&samples, dt as f32, RateSpec::Backward).unwrap();
        let sim = simulator("algebraic", dt as f32).unwrap();
        let truth = [2.0, 0.05, 0.0, 0.0];
        let mut y = vec![0.0; n];
        assert!(sim.run(&truth, &kin, &mut y));
        let mut s = 7u64;
        for v in &mut y {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            *v += 0.05 * ((s >> 33) as f64 / (1u64 << 31) as f64 - 0.5);
        }
        let cols = vec![
            Column { name: "t".into(), values: t },
            Column { name: "b".into(), values: b },
            Column { name: "torque".into(), values: y.clone() },
        ];
        let rec = Recording::from_columns(std::path::Path::new("mem"), cols, vec![]);
        let data = crate::ident::dataset::Dataset::new(&rec, &Channels::default(), 0.9, None).unwrap();
        let sp = crate::models::host("algebraic").unwrap().spec(&data.scales(), Some(RateSpec::Backward)).unwrap();
        let rows = data.train_rows();
        let obj = Objective::new(sim.as_ref(), &sp, &kin, &y, &rows, 1.0);
        let p = crate::ident::fit::linear::solve("algebraic", &kin, &y, &rows, &sp.free(), &sp.start()).unwrap();
        let flagged: Vec<usize> = spanning_zero(&obj, &p).iter().map(|u| u.0).collect();
        assert!(!flagged.contains(&0) && !flagged.contains(&1), "k or c flagged: {flagged:?} at {p:?}");
        assert!(flagged.iter().any(|j| *j == 2 || *j == 3), "neither α nor T₀ flagged at {p:?}");
        let names = ["k", "c", "alpha", "t0"];
        let w = warning(&names, &spanning_zero(&obj, &p)).unwrap();
        assert!(w.contains("cannot tell") && (w.contains("alpha =") || w.contains("t0 =")), "{w}");
    }
}
