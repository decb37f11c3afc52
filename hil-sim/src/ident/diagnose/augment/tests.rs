//! Unit tests of [`super`]: the maps of the input made again through the transforms, and
//! the refits on the first rows.

use super::super::play::play;
use super::*;

#[test]
fn a_map_of_the_input_is_made_again_from_the_input_through_the_transforms_it_follows() {
    let x: Vec<f64> = (0..300).map(|i| 0.8 * (i as f64 * 0.03).sin()).collect();
    use rand::SeedableRng;
    let rng = &mut rand::rngs::StdRng::seed_from_u64(1);
    let data = crate::ident::diagnose::tests::with_noise(x.clone(), &vec![0.0; x.len()], rng);
    let spec = crate::models::host("algebraic").and_then(|h| h.spec(&data.scales(), None)).unwrap();
    let sim = crate::ident::fit::simulate::simulator("algebraic", 1e-3).unwrap();
    let prob = Problem::new(&data, (sim.as_ref(), &spec), spec.rate, vec![], 50.0);
    let (sat, lag) = (Transform::Saturate { b_sat: 0.4 }, Transform::Lag { tau_s: 0.02 });
    let both = [sat.clone(), lag.clone()];
    let seen = prob.transformed(&both);
    let lagged = lag.apply(&x, 1e-3);
    let level = InputMap::LevelPower { x_ref: 0.8, p: 1.5 };
    let terms = vec![
        Term::of_input("play", InputMap::Play { radius: 0.1 }, &x),
        Term::of_input("level", level, &x),
        Term::additive("fixed", x.clone()),
        Term::of_input("play", InputMap::Play { radius: 0.03 }, &x),
    ];
    let after = prob.through(terms, &both, &seen);
    // The plays follow both (each its own); the level term the lag only; the plain term neither.
    assert_eq!((&after[0].values, &after[3].values), (&play(&seen, 0.1), &play(&seen, 0.03)));
    assert_ne!(after[0].values, play(&x, 0.1));
    assert_eq!(after[1].values, level.values(&lagged));
    assert!((after[1].values[52] - 0.8 * (lagged[52] / 0.8).powf(1.5)).abs() < 1e-12);
    assert_eq!(after[2].values, x);
}

/// A profile's refit on the first rows only ([`Problem::refit_train`]) ends at the same
/// θ with the same training MSE as the whole refit, to the bit: with additive terms, a
/// map of the input following a lag, a term scaled by the model, and the output's
/// saturation (whose column needs the whole run); and again once the base's runs are
/// kept ([`super::super::runs`]), on a problem that has already run them.
#[test]
fn a_refit_on_the_first_rows_ends_where_the_whole_refit_does() {
    use rand::SeedableRng;
    let n = 3000;
    let x: Vec<f64> = (0..n).map(|i| 0.6 * (i as f64 * 0.011).sin() + 0.2 * (i as f64 * 0.037).sin()).collect();
    let y: Vec<f64> = x.iter().enumerate().map(|(i, v)| 2.0 * v + 0.3 * (i as f64 * 0.002).cos()).collect();
    let rng = &mut rand::rngs::StdRng::seed_from_u64(5);
    let data = crate::ident::diagnose::tests::with_noise(x.clone(), &y, rng);
    let spec = crate::models::host("tanh").and_then(|h| h.spec(&data.scales(), None)).unwrap();
    let sim = crate::ident::fit::simulate::simulator("tanh", 1e-3).unwrap();
    // The first 900 rows of a problem trained on 2100, with nothing run yet.
    let fresh = || Problem::new(&data, (sim.as_ref(), &spec), spec.rate, (0..2100).collect(), 50.0);
    let fresh = || fresh().on_rows((0..900).collect());
    let kept = fresh();
    let drift: Vec<f64> = (0..n).map(|i| i as f64 / n as f64).collect();
    let lag = [Transform::Lag { tau_s: 0.004 }];
    let cases: Vec<Vec<Term>> = vec![
        vec![],
        vec![Term::additive("drift", drift.clone()), Term::of_input("level", InputMap::Cube { x_ref: 0.8 }, &x)],
        vec![Term::scaling("scaled", drift), Term::output_saturation("sat", 0.5)],
    ];
    let theta = spec.params.iter().map(|p| p.start).collect::<Vec<_>>();
    let bits = |v: &[f64]| v.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    for terms in &cases {
        let (f, _) = fresh().refit(&lag, terms, None, &theta, 3).unwrap();
        for _ in 0..2 {
            let (t, mse) = kept.refit_train(&lag, terms, &theta, 3).unwrap();
            let (again, _) = kept.refit(&lag, terms, None, &theta, 3).unwrap();
            assert_eq!(bits(&t), bits(&f.theta), "{}", terms.len());
            assert_eq!(mse.to_bits(), f.train_mse.to_bits(), "{}", terms.len());
            assert_eq!(bits(&again.pred), bits(&f.pred), "{}", terms.len());
            assert!(mse.is_finite() && mse > 0.0);
        }
    }
}
