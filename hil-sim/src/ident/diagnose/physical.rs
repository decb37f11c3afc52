//! Whether a candidate's fitted values are physically possible: a finding is never a
//! negative mass or inertia, a time constant or saturation level that is not positive, a
//! yield-stress saturation that expands the torque instead or turns it down at the top,
//! a loop that narrows both ways from the mean of a field of one polarity (at its low end
//! too), or a lag, delay or channel lag pinned at the edge of its search range (the refit
//! wanted more than the range allows: the term is standing in for something else).
//!
//! And what a fitted candidate stands for ([`reading`]): the catalog's asymmetry is a loop
//! *widening* with the input; a direction or loading-branch term that *narrows* the loop as a
//! field of one polarity grows, or the squared form narrowing it towards both ends of a
//! two-sided field, is the yield stress levelling off at high field, a `saturation`.

use super::augment::Fitted;
use super::candidates::{Candidate, DIRECTION_SQUARED_TERM, DIRECTION_TERM, LOADING_TERM};

/// A field whose negative side reaches at most this share of its top is of positive polarity
/// (crossing zero only by an offset or noise).
pub const ONE_SIDED: f64 = 0.1;

/// Whether the field `x` is two-sided: each polarity reaches beyond [`ONE_SIDED`] of the other's top.
fn two_sided(x: &[f64]) -> bool {
    let (lo, hi) = crate::numerics::stats::min_max(x);
    lo < -ONE_SIDED * hi && hi > -ONE_SIDED * lo
}

/// What a fitted candidate stands for: its effect and its label in words.
#[derive(Clone, Debug, PartialEq)]
pub struct Reading {
    pub effect: &'static str,
    pub label: String,
    /// A direction term (linear, loading-branch or squared) read as the loop narrowing at high level.
    pub narrowing: bool,
}

/// The candidate `c` as fitted (`f`, with `n_old` terms of the reference before its own) on
/// the input `x`: a direction or loading-branch term whose loop narrows as a field of one
/// polarity grows ([`narrowing_loop`]), or a squared direction term narrowing it towards both
/// ends of a two-sided field, is a `saturation`, the loop's width (the yield stress) levelling
/// off at high field; any other candidate is its own effect.
pub fn reading(c: &Candidate, f: &Fitted, n_old: usize, x: &[f64]) -> Reading {
    match narrowing(c, f, n_old, x) {
        Some(Narrowing::Saturation(how)) => Reading {
            effect: "saturation",
            label: format!("loop narrowing as the input grows ({how})"),
            narrowing: true,
        },
        _ => Reading { effect: c.effect, label: c.label.clone(), narrowing: false },
    }
}

/// A direction term that narrows the loop as the input grows, judged: a saturation (how, in
/// words), or impossible (why).
enum Narrowing {
    Saturation(&'static str),
    Impossible(String),
}

/// The one place that tells a narrowing loop's two readings apart ([`reading`] and
/// [`impossible`] both ask it): the linear and loading-branch forms narrowing on a field of
/// one polarity, and the squared form on a two-sided field, are saturations; the squared form
/// on a field of one polarity is impossible; `None` when the candidate does not narrow the loop.
fn narrowing(c: &Candidate, f: &Fitted, n_old: usize, x: &[f64]) -> Option<Narrowing> {
    if c.effect != "asymmetry" {
        return None;
    }
    let term = f.terms.get(n_old)?.name.as_str();
    let why = narrowing_loop(term, f.beta.get(n_old).copied().unwrap_or(0.0), x)?;
    Some(match term {
        DIRECTION_TERM => Narrowing::Saturation("loading/unloading difference shrinking at high input"),
        LOADING_TERM => Narrowing::Saturation("loading branch lowered at high input"),
        _ if two_sided(x) => {
            Narrowing::Saturation("loading/unloading difference shrinking towards both ends of a two-sided input")
        }
        _ => Narrowing::Impossible(why),
    })
}

/// Why the fitted candidate is impossible (in words, with the value and its unit), or
/// `None` when it is possible. `n_old` is the number of terms the reference already had;
/// `dt` the sample interval (s): a delay shorter than one sample is no finding, since a base
/// model stepped once per sample lags its own state by up to that much; `x` the input.
pub fn impossible(c: &Candidate, f: &Fitted, n_old: usize, value: f64, dt: f64, x: &[f64]) -> Option<String> {
    let coef = f.beta.get(n_old).copied().unwrap_or(0.0);
    if let Some(Narrowing::Impossible(why)) = narrowing(c, f, n_old, x) {
        return Some(why);
    }
    if c.effect == "inertia" && coef < 0.0 {
        return Some(format!("a negative mass or inertia ({})", crate::numerics::number::num(coef, 4)));
    }
    if c.grid_name.as_deref() == Some("t_sat") {
        if coef <= 0.0 {
            return Some(format!(
                "a torque growing faster, not levelling off, at high level (k = {})",
                crate::numerics::number::num(coef, 4)
            ));
        }
        // The map `u − k·(u − u/√(1 + (u/T_s)²))` must not turn down over the model's range:
        // its slope at the top, `1 − k·(1 − (1 + (u/T_s)²)^(−3/2))`, stays ≥ 0.
        let (lo, hi) = crate::numerics::stats::min_max(&f.model);
        let r = (hi - lo) / value.max(1e-300);
        let slope = 1.0 - coef * (1.0 - (1.0 + r * r).powf(-1.5));
        if slope < 0.0 {
            return Some(format!(
                "a saturation that turns the torque down at high level (slope {slope:.2} at the top, k = {})",
                crate::numerics::number::num(coef, 4)
            ));
        }
    }
    let name = c.grid_name.as_deref()?;
    if c.grid.len() < 2 {
        return None;
    }
    let (lo, hi) = c.bounds();
    let at = |edge: f64| (value - edge).abs() <= 1e-3 * (hi - lo).abs().max(1e-300);
    match name {
        "tau_s" | "lag_s" if value < 0.0 => Some(format!("a negative time constant ({:.2} ms)", 1e3 * value)),
        "tau_s" | "lag_s" if value > 0.0 && at(hi) => {
            Some(format!("a time constant at the edge of its search range ({:.1} ms)", 1e3 * value))
        }
        "delay_s" if value.abs() < dt => Some(format!(
            "a delay shorter than one sample ({:+.2} ms): the base model's own discretisation shifts it by as much",
            1e3 * value
        )),
        "delay_s" if at(hi) || at(lo) => {
            Some(format!("a delay at the edge of its search range ({:+.2} ms)", 1e3 * value))
        }
        "b_sat" if value <= 0.0 => {
            Some(format!("a saturation level that is not positive ({})", crate::numerics::number::num(value, 4)))
        }
        _ => None,
    }
}

/// Why an asymmetry term of coefficient `coef` makes the loop *narrower* as the input `x`
/// grows, if it does. The term `δ·(x − x̄)·sgn(ẋ)` adds `2δ·(x − x̄)` to the loop's width:
/// on a field of positive polarity (its negative side, if any, within [`ONE_SIDED`] of its
/// top: an offset or noise) δ < 0 narrows it towards the top, where the catalog's asymmetry
/// ("loop width growing with the input") and the physics (a width growing with |x|) both
/// widen it. On a negative or two-sided field the two readings part (the catalog's signed
/// `δ·x` with δ > 0 narrows the loop towards a large negative field), so either sign is
/// possible there. The loading branch lifted, `δ_l·(x − x_min)·(1 + sgn(ẋ))/2`, widens the
/// loop by `δ_l·(x − x_min)` and is judged alike. `δ₂·(x − x̄)²·sgn(ẋ)` with δ₂ < 0 narrows
/// it both ways from x̄: on a two-sided field that is a saturation at both polarities
/// ([`reading`]); on a field of one polarity it narrows the low end too.
fn narrowing_loop(term: &str, coef: f64, x: &[f64]) -> Option<String> {
    let (lo, hi) = crate::numerics::stats::min_max(x);
    let positive = hi > 0.0 && lo >= -ONE_SIDED * hi;
    let narrows = match term {
        DIRECTION_TERM | LOADING_TERM => positive && coef < 0.0,
        DIRECTION_SQUARED_TERM => coef < 0.0,
        _ => false,
    };
    let coef = crate::numerics::number::num(coef, 4);
    narrows.then(|| match term {
        DIRECTION_SQUARED_TERM => format!(
            "a loop narrowing both ways from the input's mean ({term} = {coef}): on a field of one polarity at its low \
             end too, neither a widening asymmetry nor a saturation"
        ),
        _ => format!(
            "a loop narrowing as the input grows ({term} = {coef}): the output levelling off at high level, a saturation's sign"
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ident::diagnose::augment::Term;
    use crate::ident::diagnose::candidates::{Piece, DELAY_BOX};
    use crate::ident::diagnose::transform::Transform;

    /// The yield-stress candidate, and a model spanning 0–4 N·m refitted with its term at
    /// coefficient `k`.
    fn case(k: f64) -> (Candidate, Fitted) {
        let c = Candidate {
            effect: "saturation",
            label: "saturating torque at high level (yield stress)".into(),
            grid_name: Some("t_sat".into()),
            grid: vec![1.0, 10.0],
            build: Box::new(|t| Piece { transform: None, terms: vec![Term::output_saturation("k_sat", t)] }),
            channel: None,
        };
        let f = Fitted {
            transforms: vec![],
            terms: vec![Term::output_saturation("k_sat", 2.0)],
            theta: vec![],
            beta: vec![k],
            model: (0..=100).map(|i| f64::from(i) * 0.04).collect(),
            pred: vec![],
            train_mse: 0.0,
        };
        (c, f)
    }

    #[test]
    fn a_yield_stress_saturation_levels_off_and_never_turns_down() {
        // Over 4 N·m with T_s = 2 N·m the map's slope at the top is 1 − k·(1 − 5^(−3/2)):
        // positive for k below 1.1.
        let why = |k: f64| {
            let (c, f) = case(k);
            impossible(&c, &f, 0, 2.0, 1e-3, &[])
        };
        assert_eq!(why(1.0), None);
        assert!(why(1.5).is_some_and(|w| w.contains("turns the torque down")), "{:?}", why(1.5));
        assert!(why(-0.2).is_some_and(|w| w.contains("growing faster")), "{:?}", why(-0.2));
    }

    #[test]
    fn an_asymmetry_may_widen_the_loop_with_the_input_but_not_narrow_it() {
        let positive: Vec<f64> = (0..=100).map(|i| 0.05 + 0.005 * f64::from(i)).collect();
        let crossing_by_noise: Vec<f64> = positive.iter().map(|v| v - 0.08).collect();
        let negative: Vec<f64> = positive.iter().map(|v| -v).collect();
        // A bench recording's field of negative polarity, -0.50 to 0.045 T.
        let mostly_negative: Vec<f64> = (0..=100).map(|i| -0.5 + 0.00545 * f64::from(i)).collect();
        let two_sided: Vec<f64> = (0..=100).map(|i| -0.5 + 0.01 * f64::from(i)).collect();
        assert_eq!(narrowing_loop(DIRECTION_TERM, 0.3, &positive), None);
        assert!(narrowing_loop(DIRECTION_TERM, -0.3, &positive).is_some_and(|w| w.contains("saturation")));
        assert!(narrowing_loop(DIRECTION_TERM, -0.3, &crossing_by_noise).is_some());
        assert!(narrowing_loop(LOADING_TERM, -0.3, &positive).is_some());
        assert_eq!(narrowing_loop(LOADING_TERM, 0.3, &positive), None);
        assert_eq!(narrowing_loop(LOADING_TERM, -0.3, &two_sided), None);
        // Where the catalog's signed δ·x and a width growing with |x| part, either sign.
        for x in [&negative, &mostly_negative, &two_sided] {
            assert_eq!(narrowing_loop(DIRECTION_TERM, -0.3, x), None);
            assert_eq!(narrowing_loop(DIRECTION_TERM, 0.3, x), None);
        }
        assert!(narrowing_loop(DIRECTION_SQUARED_TERM, -0.3, &two_sided).is_some());
        assert!(narrowing_loop(DIRECTION_SQUARED_TERM, -0.3, &positive).is_some());
        assert_eq!(narrowing_loop(DIRECTION_SQUARED_TERM, 0.3, &positive), None);
        assert_eq!(narrowing_loop("c_rate", -0.3, &positive), None);
    }

    /// A direction (or loading-branch, or squared) candidate refitted with coefficient `k` on
    /// the input `x`.
    fn direction(term: &'static str, k: f64, x: &[f64]) -> (Candidate, Fitted) {
        let v = x.to_vec();
        let c = Candidate {
            effect: "asymmetry",
            label: "loading/unloading difference growing with the input".into(),
            grid_name: None,
            grid: vec![0.0],
            build: Box::new(move |_| Piece { transform: None, terms: vec![Term::additive(term, v.clone())] }),
            channel: None,
        };
        let f = Fitted {
            transforms: vec![],
            terms: vec![Term::additive(term, x.to_vec())],
            theta: vec![],
            beta: vec![k],
            model: x.to_vec(),
            pred: vec![],
            train_mse: 0.0,
        };
        (c, f)
    }

    #[test]
    fn a_loop_narrowing_as_a_one_sided_field_grows_is_read_as_a_saturation() {
        let positive: Vec<f64> = (0..=100).map(|i| 0.05 + 0.005 * f64::from(i)).collect();
        let two_sided: Vec<f64> = (0..=100).map(|i| -0.5 + 0.01 * f64::from(i)).collect();
        let read = |term, k, x: &[f64]| {
            let (c, f) = direction(term, k, x);
            (reading(&c, &f, 0, x), impossible(&c, &f, 0, 0.0, 1e-3, x))
        };
        for term in [DIRECTION_TERM, LOADING_TERM] {
            let (r, why) = read(term, -0.3, &positive);
            assert_eq!((r.effect, r.narrowing, why), ("saturation", true, None), "{term}");
            assert!(r.label.starts_with("loop narrowing as the input grows"), "{}", r.label);
            let (r, why) = read(term, 0.3, &positive);
            assert_eq!((r.effect, r.narrowing, why), ("asymmetry", false, None), "{term}");
        }
        // On a two-sided field either sign of the linear form is an asymmetry.
        let (r, why) = read(DIRECTION_TERM, -0.3, &two_sided);
        assert_eq!((r.effect, why), ("asymmetry", None));
        // The squared form narrowing towards both ends is a saturation on a two-sided field;
        // on a field of one polarity it narrows the low end too: impossible, and no saturation.
        let (r, why) = read(DIRECTION_SQUARED_TERM, -0.3, &two_sided);
        assert_eq!((r.effect, r.narrowing, why), ("saturation", true, None));
        let (r, why) = read(DIRECTION_SQUARED_TERM, 0.3, &two_sided);
        assert_eq!((r.effect, why), ("asymmetry", None));
        let (r, why) = read(DIRECTION_SQUARED_TERM, -0.3, &positive);
        assert_eq!(r.effect, "asymmetry");
        assert!(why.is_some_and(|w| w.contains("narrowing")));
    }

    #[test]
    fn a_delay_past_its_grid_is_refitted_and_pinned_only_at_the_box() {
        // The grid ±30 ms in 1 ms steps at 1 kHz; the box is DELAY_BOX times that.
        let c = Candidate {
            effect: "transport_delay",
            label: "time shift between input and output".into(),
            grid_name: Some("delay_s".into()),
            grid: (-30..=30).filter(|k| *k != 0).map(|k| f64::from(k) * 1e-3).collect(),
            build: Box::new(|d| Piece { transform: Some(Transform::Delay { delay_s: d }), terms: vec![] }),
            channel: None,
        };
        let (lo, hi) = c.bounds();
        assert!((lo + 0.03 * DELAY_BOX).abs() < 1e-12 && (hi - 0.03 * DELAY_BOX).abs() < 1e-12, "{lo} {hi}");
        let f = Fitted {
            transforms: vec![],
            terms: vec![],
            theta: vec![],
            beta: vec![],
            model: vec![],
            pred: vec![],
            train_mse: 0.0,
        };
        let why = |d: f64| impossible(&c, &f, 0, d, 1e-3, &[]);
        // A delay at the grid's end (the largest a bench or a logger may give) is possible.
        for d in [0.03, -0.03, 0.0312, 0.04] {
            assert_eq!(why(d), None, "{d}");
        }
        for d in [hi, lo] {
            assert!(why(d).is_some_and(|w| w.contains("edge of its search range")), "{d}: {:?}", why(d));
        }
        assert!(why(0.0004).is_some_and(|w| w.contains("shorter than one sample")));
    }
}
