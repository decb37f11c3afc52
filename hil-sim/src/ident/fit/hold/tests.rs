use super::*;
use crate::ident::fit::simulate::{kinematics, simulator};
use crate::ident::fit::{fit, DelayChoice, FitOptions};
use crate::io::recording::{Channels, Column, Recording};
use crate::models::RateSpec;

/// A tanh-model recording (seed 000 eq. 11–12: `α·tanh(β·ẋ + γ·sign x) + c·ẋ + k·x + T₀`)
/// with stiffness `k`, plus uniform noise of ±0.05.
fn tanh_data(k: f64) -> crate::ident::dataset::Dataset {
    let (n, dt) = (6000, 1e-3);
    let t: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
    let b: Vec<f64> = t.iter().map(|t| (6.0 * t).sin() + 0.3 * (23.0 * t).sin()).collect();
    let samples: Vec<model_core::Sample> = b.iter().map(|v| model_core::Sample::new(*v as f32)).collect();
    let kin = kinematics(&samples, dt as f32, RateSpec::Backward).unwrap();
    let sim = simulator("tanh", dt as f32).unwrap();
    let truth = [2.0, 0.5, 0.2, 0.05, k, 0.3];
    let mut y = vec![0.0; n];
    assert!(sim.run(&truth, &kin, &mut y));
    let mut s = 11u64;
    for v in &mut y {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        *v += 0.1 * ((s >> 33) as f64 / (1u64 << 31) as f64 - 0.5);
    }
    let cols = vec![
        Column { name: "t".into(), values: t },
        Column { name: "b".into(), values: b },
        Column { name: "torque".into(), values: y },
    ];
    let rec = Recording::from_columns(std::path::Path::new("mem"), cols, vec![]);
    crate::ident::dataset::Dataset::new(&rec, &Channels::default(), 0.8, None).unwrap()
}

fn opts() -> FitOptions {
    FitOptions { delay: DelayChoice::Off, rate: Some(RateSpec::Backward), ..FitOptions::default() }
}

#[test]
fn an_absent_stiffness_is_held_at_zero_and_named() {
    let r = fit("tanh", &tanh_data(0.0), &opts()).unwrap();
    assert!(r.held_params.iter().any(|p| p == "k"), "k not held: {:?} {:?} {:?}", r.held_params, r.flat, r.warnings);
    assert_eq!(r.flat[4], 0.0, "{:?}", r.flat);
    let w = r.warnings.iter().find(|w| w.contains("held at 0")).expect("a warning saying what is held");
    assert!(w.contains("k = ") && w.contains("cannot tell"), "{w}");
    // The held fit is as good as the truth allows: R² on held-out data close to the noiseless limit.
    assert!(r.heldout.r2 > 0.99, "{:?}", r.heldout);
    assert_eq!(r.free_params, 6 - r.held_params.len());
    let json = serde_json::to_value(&r).unwrap();
    assert!(json["held_params"].as_array().is_some_and(|a| a.iter().any(|v| v == "k")), "{json}");
}

#[test]
fn a_present_stiffness_is_fitted_not_held() {
    let r = fit("tanh", &tanh_data(1.5), &opts()).unwrap();
    assert!(!r.held_params.iter().any(|p| p == "k"), "k held: {:?} {:?}", r.held_params, r.warnings);
    assert!((r.flat[4] - 1.5).abs() < 0.15, "k = {} (truth 1.5)", r.flat[4]);
    assert!(r.warnings.iter().all(|w| !w.contains("k = ")), "{:?}", r.warnings);
}

#[test]
fn the_warning_names_held_and_undetermined_parameters() {
    let names = ["a", "b", "c"];
    let un = [(0, 0.1, 0.5), (2, -0.2, 3.0)];
    let w = warning(&names, &un, Some((&[2], 0.004)));
    assert!(w.contains("a = 0.1000 ± 0.5000") && w.contains("c = -0.2000 ± 3.0000"), "{w}");
    assert!(w.contains("c held at 0") && w.contains("+0.40 %"), "{w}");
    assert!(w.contains("a not held") && w.contains("treat it as undetermined"), "{w}");
    let none = warning(&names, &un, None);
    assert!(!none.contains("held at 0") && none.contains("a, c not held"), "{none}");
}
