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
//! concave map) stays for the rounds to find. It is a map of the input
//! ([`super::augment::InputMap`]): a candidate's lag or delay of the input reaches it as it
//! reaches the base model (a saturating map or an offset does not: composed with the one
//! exponent fitted here it would be a second curvature, [`super::augment::InputMap::follows`]).

use super::augment::{Fitted, InputMap, Problem, Term, Tune};

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
    let build = move |p: f64| (None, vec![Term::of_input("level_power", InputMap::LevelPower { x_ref, p }, x)]);
    let tune = Tune { build: &build, start: 1.5, lo: P_MIN, hi: P_MAX, log: false };
    let (with_map, p) = prob.refit(&current.transforms, &current.terms, Some(&tune), &current.theta, ITERATIONS)?;
    let beta = with_map.beta.get(current.terms.len()).copied().unwrap_or(0.0);
    // The term's β is counted by the criterion; its exponent p is one more parameter.
    let n = prob.train.len();
    let bic_gain = super::rank::bic(n, &reference) - super::rank::bic(n, &with_map) - (n as f64).ln();
    let better = heldout_rmse(&with_map.pred) < heldout_rmse(&reference.pred);
    (bic_gain > 0.0 && better && beta > 0.0).then_some((with_map, p))
}

/// The note a diagnosis carries when the base `id` got the level term of exponent `p`
/// (`names`: the input's and the output's).
pub fn note(id: &str, (input, output): (&str, &str), p: f64) -> String {
    format!(
        "the base model {id} was given a static term in the {input} to the power {p:.2}: the {output} grows faster \
         than linearly with it, and every candidate was judged on top of that term"
    )
}

#[cfg(test)]
mod tests {
    use crate::ident::diagnose::tests::recording_with;
    use crate::ident::diagnose::{diagnose, DiagnoseOptions, InputTransform};
    use crate::ident::fit::Dataset;

    /// A unipolar three-tone field, 0.3–1.7.
    fn field(t: f64) -> f64 {
        let tone = |f: f64, a: f64, ph: f64| a * (2.0 * std::f64::consts::PI * f * t + ph).sin();
        1.0 + tone(2.0, 0.6, 0.0) + tone(7.3, 0.3, 1.0) + tone(13.1, 0.1, 2.0)
    }

    fn notes_and_findings(d: &Dataset) -> (Vec<String>, Vec<String>) {
        let opts = DiagnoseOptions { model: Some("bouc_wen".into()), ..Default::default() };
        let d = diagnose(d, vec![], None, ("b", "torque"), &opts, &crate::progress::NoProgress).unwrap();
        (d.notes, d.findings.into_iter().map(|f| f.effect).collect())
    }

    #[test]
    fn a_torque_growing_faster_than_the_field_is_part_of_the_base_not_a_finding() {
        // 1.5·x^1.7 on a field of 0.3–1.7: about a third of the torque's span.
        let (notes, findings) = notes_and_findings(&recording_with(field, None, |x| 1.5 * x.abs().powf(1.7), 3));
        assert!(notes.iter().any(|n| n.contains("to the power")), "{notes:?}");
        assert!(findings.is_empty(), "{findings:?}");
    }

    #[test]
    fn a_saturating_field_is_not_taken_for_a_level_term() {
        let sat = InputTransform::Saturate { b_sat: 1.2 };
        let (notes, findings) = notes_and_findings(&recording_with(field, Some(sat), |_| 0.0, 4));
        assert!(!notes.iter().any(|n| n.contains("to the power")), "{notes:?}");
        assert_eq!(findings.first().map(String::as_str), Some("saturation"), "{findings:?}");
    }
}
