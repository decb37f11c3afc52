use super::*;
use crate::models::replay;

/// A recording of `id` with `truth`, whose input channel was logged `lag` samples late.
fn lagged(id: &str, truth: &[f32], lag: f64, command: bool) -> Dataset {
    let dt = 1e-3;
    let n = 6000;
    let time: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
    let x_true: Vec<f64> = time
        .iter()
        .map(|t| (2.0 * std::f64::consts::PI * 3.0 * t).sin() + 0.4 * (2.0 * std::f64::consts::PI * 11.0 * t).sin())
        .collect();
    let u = command.then(|| time.iter().map(|t| 1.0 + 0.8 * (3.1 * t).sin()).collect::<Vec<f64>>());
    let samples = crate::models::replay::samples(&x_true, u.as_deref());
    let out = replay(id, truth, dt as f32, RateSpec::Backward, &samples).unwrap();
    // The logged input is the true one `lag` samples late: x_log(t) = x_true(t − lag).
    let input = crate::models::alignment::shift(&x_true, -lag);
    Dataset {
        dt,
        time,
        input,
        output: out.y.iter().map(|v| f64::from(*v)).collect(),
        command: u,
        train_end: 4200,
        excluded: vec![false; n],
        unusable: Vec::new(),
        rates: None,
        runs: Vec::new(),
    }
}

fn opts(delay: DelayChoice) -> FitOptions {
    // Noiseless data: let Levenberg–Marquardt run to convergence.
    FitOptions {
        rate: Some(RateSpec::Backward),
        delay,
        lm_iterations: 80,
        polish_iterations: 80,
        ..FitOptions::default()
    }
}

#[test]
fn closed_form_fit_finds_a_known_input_delay() {
    let data = lagged("algebraic", &[2.0, 0.05, -0.3, 0.1], 3.0, false);
    let auto = fit("algebraic", &data, &opts(DelayChoice::Auto)).unwrap();
    let off = fit("algebraic", &data, &opts(DelayChoice::Off)).unwrap();
    assert!((auto.delay_s - 3e-3).abs() < 0.3e-3, "delay {} s", auto.delay_s);
    assert_eq!(off.delay_s, 0.0);
    assert!(auto.heldout.rmse < 1e-3 * off.heldout.rmse, "{} vs {}", auto.heldout.rmse, off.heldout.rmse);
}

#[test]
fn iterative_fit_finds_a_known_input_delay() {
    let truth = [3.0, 2.0, 1.0, 1.0, 2.0, 0.4, 0.8, 0.0];
    let data = lagged("bouc_wen", &truth, -2.5, false);
    let auto = fit("bouc_wen", &data, &opts(DelayChoice::Auto)).unwrap();
    let off = fit("bouc_wen", &data, &opts(DelayChoice::Off)).unwrap();
    assert!(
        (auto.delay_s + 2.5e-3).abs() < 0.5e-3,
        "delay {} s, rmse {} vs {}",
        auto.delay_s,
        auto.train.rmse,
        off.train.rmse
    );
    assert_eq!(auto.command_delay_s, 0.0, "no command channel, no command delay");
    assert!(auto.train.rmse < off.train.rmse, "{} vs {}", auto.train.rmse, off.train.rmse);
    // A given delay is used as given.
    let fixed = fit("bouc_wen", &data, &opts(DelayChoice::Fixed(-2.5e-3, 0.0))).unwrap();
    assert!((fixed.delay_s + 2.5e-3).abs() < 1e-12);
}

/// A delay beyond the search range ends at its edge: it is held at zero, named, and the
/// model refitted from the first search's parameters, which finds as good a fit as a whole
/// new search with the delay at zero for a fraction of its runs.
#[test]
fn a_delay_at_the_edge_is_held_at_zero_and_refitted_from_the_first_search() {
    let truth = [3.0, 2.0, 1.0, 1.0, 2.0, 0.4, 0.8, 0.0];
    let data = lagged("bouc_wen", &truth, 14.0, false);
    let auto = fit("bouc_wen", &data, &opts(DelayChoice::Auto)).unwrap();
    let zero = fit("bouc_wen", &data, &opts(DelayChoice::Fixed(0.0, 0.0))).unwrap();
    assert_eq!(auto.delay_s, 0.0);
    assert!(auto.warnings.iter().any(|w| w.contains("input delay") && w.contains("edge")), "{:?}", auto.warnings);
    assert!(
        auto.train.rmse <= 1.02 * zero.train.rmse,
        "warm refit {} vs new search {}",
        auto.train.rmse,
        zero.train.rmse
    );
    // The first search plus the refit cost less than one and a half new searches (two before).
    assert!(2 * auto.evaluations < 3 * zero.evaluations, "{} vs {} runs", auto.evaluations, zero.evaluations);
}

/// Seed 000 fits the clutch with a Bouc–Wen loop of exponent `n = 1`: the search's variant
/// finds it and the result says so (`FitResult::variant`, which a diagnosis refits on). A
/// loop of `n = 2` keeps the model's spec.
#[test]
fn a_bouc_wen_loop_of_exponent_one_is_fitted_with_it() {
    for n in [1.0f32, 2.0] {
        let data = lagged("bouc_wen", &[3.0, 2.0, 1.0, 1.0, n, 0.4, 0.8, 0.0], 0.0, false);
        let r = fit("bouc_wen", &data, &opts(DelayChoice::Off)).unwrap();
        assert_eq!(r.flat[4], f64::from(n), "n = {n}: {:?}", r.flat);
        assert_eq!(r.variant, if n == 1.0 { 1 } else { 0 });
        assert!(r.heldout.r_rmse < 1e-3, "n = {n}: held-out R-RMSE {}", r.heldout.r_rmse);
    }
}
