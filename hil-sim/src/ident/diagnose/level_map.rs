//! Before the rounds: a static power-law term of the input added to the base model,
//! `β·x_ref·sgn(x)·|x/x_ref|^p` with `p` in ([`P_MIN`], [`P_MAX`]) and `β > 0`, kept when it helps.
//!
//! Most seed models are linear in the field, while an MR fluid's yield stress grows faster
//! than linearly with it below saturation (τ_y ∝ B^p, p ≈ 1.5). Left in the base residual,
//! that curvature is a misfit every candidate of the catalog would try to explain (a
//! direction term, a rate term, a lag): it is absorbed first, as part of the base, and
//! reported as a note, not as a finding. The term is added to the output, not fed through
//! the model (a power of the input would also scale the model's rate terms with the level),
//! and only with `β > 0`: it cannot bend the curve the other way, so a saturation (a
//! concave map) stays for the rounds to find.

use super::augment::{Fitted, Problem, Term, Tune};

/// The exponents tried.
pub const P_MIN: f64 = 1.1;
pub const P_MAX: f64 = 3.0;
/// Gauss–Newton iterations of the refit with the map (and of the reference without it).
const ITERATIONS: usize = 6;

/// The base with the level term and its exponent, when the term lowers the training error by
/// more than its two parameters cost (BIC) and lowers the held-out error too
/// (`heldout_rmse` scores a prediction); `None` otherwise.
pub fn fit(prob: &Problem<'_>, current: &Fitted, heldout_rmse: impl Fn(&[f64]) -> f64) -> Option<(Fitted, f64)> {
    let x_ref = prob.data.input.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    if x_ref <= 0.0 || !x_ref.is_finite() {
        return None;
    }
    let reference = prob.refit(&current.transforms, &current.terms, None, &current.theta, ITERATIONS)?.0;
    let x = &prob.data.input;
    let build = move |p: f64| {
        let v: Vec<f64> = x.iter().map(|v| x_ref * v.signum() * (v.abs() / x_ref).powf(p)).collect();
        (None, vec![Term::additive("level_power", v)])
    };
    let tune = Tune { build: &build, start: 1.5, lo: P_MIN, hi: P_MAX, log: false };
    let (with_map, p) = prob.refit(&current.transforms, &current.terms, Some(&tune), &current.theta, ITERATIONS)?;
    let beta = with_map.beta.get(current.terms.len()).copied().unwrap_or(0.0);
    let n = prob.train.len() as f64;
    // Two extra parameters: β and p.
    let bic_gain = n * (reference.train_mse.max(1e-300) / with_map.train_mse.max(1e-300)).ln() - 2.0 * n.ln();
    let better = heldout_rmse(&with_map.pred) < heldout_rmse(&reference.pred);
    (bic_gain > 0.0 && better && beta > 0.0).then_some((with_map, p))
}

#[cfg(test)]
mod tests {
    use crate::ident::diagnose::{diagnose, DiagnoseOptions, InputTransform};
    use crate::ident::fit::Dataset;
    use crate::models::RateSpec;
    use rand::{Rng, SeedableRng};

    /// A Bouc–Wen recording (model-core's, a three-tone input, 0.5 % noise) whose model is fed
    /// the input through `seen` and whose torque gets `extra(x)` on top.
    fn recording(seen: Option<InputTransform>, extra: impl Fn(f64) -> f64, seed: u64) -> Dataset {
        let (dt, n) = (1e-3, 12_000);
        let time: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
        let tone = |t: f64, f: f64, a: f64, ph: f64| a * (2.0 * std::f64::consts::PI * f * t + ph).sin();
        let x: Vec<f64> = time
            .iter()
            .map(|&t| 1.0 + 0.6 * tone(t, 2.0, 1.0, 0.0) + tone(t, 7.3, 0.3, 1.0) + tone(t, 13.1, 0.1, 2.0))
            .collect();
        let fed = seen.map_or_else(|| x.clone(), |s| s.apply(&x, dt));
        let rates = crate::numerics::derivative::rates(&fed, dt);
        let samples = crate::models::replay::samples_with_rates(&fed, None, Some(&rates));
        let truth = [3.0, 2.0, 1.0, 1.0, 2.0, 0.4, 0.8, 0.0];
        let out = crate::models::replay("bouc_wen", &truth, dt as f32, RateSpec::Backward, &samples).unwrap();
        let y: Vec<f64> = out.y.iter().zip(&x).map(|(v, x)| f64::from(*v) + extra(*x)).collect();
        let (lo, hi) = y.iter().fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let output = y.iter().map(|v| v + 0.005 * (hi - lo) * (rng.random::<f64>() - 0.5) * 12f64.sqrt()).collect();
        Dataset {
            dt,
            time,
            input: x,
            output,
            command: None,
            train_end: 8400,
            excluded: vec![false; n],
            unusable: Vec::new(),
            rates: None,
            runs: Vec::new(),
        }
    }

    fn notes_and_findings(d: &Dataset) -> (Vec<String>, Vec<String>) {
        let opts = DiagnoseOptions { model: Some("bouc_wen".into()), ..Default::default() };
        let d = diagnose(d, vec![], None, ("b", "torque"), &opts, &crate::progress::NoProgress).unwrap();
        (d.notes, d.findings.into_iter().map(|f| f.effect).collect())
    }

    #[test]
    fn a_torque_growing_faster_than_the_field_is_part_of_the_base_not_a_finding() {
        // 1.5·x^1.7 on a field of 0.3–1.7: about a third of the torque's span.
        let (notes, findings) = notes_and_findings(&recording(None, |x| 1.5 * x.abs().powf(1.7), 3));
        assert!(notes.iter().any(|n| n.contains("to the power")), "{notes:?}");
        assert!(findings.is_empty(), "{findings:?}");
    }

    #[test]
    fn a_saturating_field_is_not_taken_for_a_level_term() {
        let sat = InputTransform::Saturate { b_sat: 1.2 };
        let (notes, findings) = notes_and_findings(&recording(Some(sat), |_| 0.0, 4));
        assert!(!notes.iter().any(|n| n.contains("to the power")), "{notes:?}");
        assert_eq!(findings.first().map(String::as_str), Some("saturation"), "{findings:?}");
    }
}
