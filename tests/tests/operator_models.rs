//! Issue 7 acceptance on simulated clutch recordings (`hil-sim simulate` scenarios, run
//! through the library): every model that maps the field level to torque is identified and
//! replayed through the no_std core with a held-out R² ≥ 0.8 on the multi-sine; on seed
//! 004's asymmetric triangle loop the asymmetric operator models (GPI, Preisach) reach a
//! GOF ≥ 0.95 where the symmetric ones (classical PI, classical Bouc–Wen) do not; and the
//! fitted PI loop is inverted analytically for feed-forward; on the multi-sine, NARX
//! (seed 000 eq. 18–19, the board's size) is at least as accurate on the held-out part as
//! the best parametric model.

use std::sync::OnceLock;

use hil_sim::ident::fit::{fit, Dataset, FitOptions, FitResult};
use hil_sim::io::recording::Channels;
use hil_sim::sim::scenario::Scenario;
use model_core::models::prandtl_ishlinskii::PrandtlIshlinskii;
use model_core::{Kin, Model};

/// Record built-in scenario `name` (shortened to `duration` s when given) and split it
/// like `hil-sim fit` does (flagged samples excluded).
fn dataset(name: &str, duration: Option<f64>, ch: &Channels, train: f64) -> Dataset {
    let mut sc = Scenario::builtin(name).expect("built-in scenario");
    if let Some(d) = duration {
        sc.duration_s = d;
    }
    let rec = hil_sim::closed_loop::record::record(&sc).expect("simulation");
    let recording = rec.recording;
    hil_sim::ident::dataset::prepare_recording(recording, ch, train, false).expect("dataset").data
}

fn channels(input: &str, command: Option<&str>) -> Channels {
    Channels { input: input.into(), command: command.map(Into::into), ..Channels::default() }
}

fn fit_all(data: &Dataset, ids: &[&str]) -> Vec<FitResult> {
    ids.iter().map(|id| fit(id, data, &FitOptions::default()).unwrap_or_else(|e| panic!("{id}: {e}"))).collect()
}

/// Every model that maps the field level to torque.
const FIELD_LEVEL: [&str; 12] = [
    "algebraic",
    "bouc_wen",
    "lugre",
    "tanh",
    "dahl",
    "hammerstein_wiener",
    "narx",
    "preisach",
    "prandtl_ishlinskii",
    "gpi",
    "maxwell_slip",
    "bouc_wen_asym",
];

/// The data-driven models of seed 000 (the rest are parametric).
const DATA_DRIVEN: [&str; 2] = ["hammerstein_wiener", "narx"];

/// The multi-sine recording and every field-level model fitted to it, shared by the tests
/// that read them (the fits are the expensive part).
fn multisine_fits() -> &'static (Dataset, Vec<FitResult>) {
    static FITS: OnceLock<(Dataset, Vec<FitResult>)> = OnceLock::new();
    FITS.get_or_init(|| {
        // Hall B in, torque out; the coil current is the command (the Dahl model's
        // command-dependent terms); the scenario as `hil-sim simulate --scenario multisine` records it (40 s).
        let data = dataset("multisine", None, &channels("b", Some("i")), 0.7);
        let results = fit_all(&data, &FIELD_LEVEL);
        (data, results)
    })
}

#[test]
fn field_level_models_reach_r2_08_on_the_multisine() {
    let (data, results) = multisine_fits();
    let mut low = Vec::new();
    for r in results {
        eprintln!(
            "{:<20} held-out R² {:.4}  GOF {:.4}  fit {:.2} s",
            r.model, r.heldout.r2, r.heldout.gof, r.fit_seconds
        );
        assert!(r.heldout.n > 1000, "{}: held-out part not scored", r.model);
        assert_eq!(r.output.len(), data.len(), "{}: not replayed over the recording", r.model);
        if r.heldout.r2.is_nan() || r.heldout.r2 < 0.8 {
            low.push(format!("{}: {:.4}", r.model, r.heldout.r2));
        }
    }
    assert!(low.is_empty(), "held-out R² below 0.8: {low:?}");
}

#[test]
fn narx_is_as_accurate_as_the_best_parametric_model_on_the_multisine() {
    // Issue 7: the board's NARX against every parametric model fitted to the same
    // recording and split, on the held-out part (R² and R-RMSE).
    let (_, results) = multisine_fits();
    let narx = results.iter().find(|r| r.model == "narx").expect("narx fitted");
    let parametric: Vec<&FitResult> = results.iter().filter(|r| !DATA_DRIVEN.contains(&r.model.as_str())).collect();
    let best_r2 = parametric.iter().max_by(|a, b| a.heldout.r2.total_cmp(&b.heldout.r2)).expect("parametric fits");
    let best_rrmse =
        parametric.iter().min_by(|a, b| a.heldout.r_rmse.total_cmp(&b.heldout.r_rmse)).expect("parametric fits");
    eprintln!(
        "narx: held-out R² {:.4}, R-RMSE {:.4} (fit {:.2} s); best parametric: {} R² {:.4}, {} R-RMSE {:.4}",
        narx.heldout.r2,
        narx.heldout.r_rmse,
        narx.fit_seconds,
        best_r2.model,
        best_r2.heldout.r2,
        best_rrmse.model,
        best_rrmse.heldout.r_rmse
    );
    assert!(
        narx.heldout.r2 >= best_r2.heldout.r2,
        "narx held-out R² {:.4} < {} {:.4}",
        narx.heldout.r2,
        best_r2.model,
        best_r2.heldout.r2
    );
    assert!(
        narx.heldout.r_rmse <= best_rrmse.heldout.r_rmse,
        "narx held-out R-RMSE {:.4} > {} {:.4}",
        narx.heldout.r_rmse,
        best_rrmse.model,
        best_rrmse.heldout.r_rmse
    );
}

#[test]
fn asymmetric_loop_needs_an_asymmetric_model_and_pi_inverts() {
    let data = dataset("triangle_asym", None, &channels("i", None), 0.7);
    let results = fit_all(&data, &["gpi", "preisach", "prandtl_ishlinskii", "bouc_wen"]);
    let gof = |id: &str| results.iter().find(|r| r.model == id).map(|r| r.heldout.gof).unwrap_or(f64::NAN);
    for r in &results {
        eprintln!("{:<20} held-out GOF {:.4}  R² {:.4}", r.model, r.heldout.gof, r.heldout.r2);
    }
    for id in ["gpi", "preisach"] {
        assert!(gof(id) >= 0.95, "{id}: GOF {:.4} < 0.95", gof(id));
    }
    for id in ["prandtl_ishlinskii", "bouc_wen"] {
        // "Visibly" worse: below seed 004's 0.90 line for an adequate model, and well below
        // the asymmetric ones.
        assert!(gof(id) < 0.9 && gof(id) < gof("gpi") - 0.05, "{id}: GOF {:.4} is not visibly lower", gof(id));
    }

    // Feed-forward with the fitted classical PI model: the measured torque is the desired
    // output, its analytical inverse gives the current to command, and the forward model
    // driven by that current reproduces the desired torque.
    let pi = results.iter().find(|r| r.model == "prandtl_ishlinskii").expect("PI fitted");
    let flat: Vec<f32> = pi.flat.iter().map(|v| *v as f32).collect();
    let m = PrandtlIshlinskii::<10>::from_params(&flat, data.dt as f32).expect("valid PI set");
    let inv = m.inverse().expect("fitted PI keeps p0 > 0");
    let x0 = data.input[0] as f32;
    let fwd0 = m.initial_state(&Kin::new(x0, 0.0, 0.0, 0.0));
    let mut s_inv = inv.state_from(&fwd0);
    let mut s_fwd = fwd0;
    let desired: Vec<f32> = data.output.iter().map(|v| *v as f32).collect();
    let (lo, hi) = desired.iter().fold((f32::MAX, f32::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
    let mut worst = 0.0f32;
    for &yd in &desired {
        let x = inv.step(&mut s_inv, yd);
        assert!(x.is_finite());
        let y = m.step(&mut s_fwd, &Kin::new(x, 0.0, 0.0, 0.0));
        worst = worst.max((y - yd).abs());
    }
    assert!(worst <= 2e-3 * (hi - lo), "inverse then forward misses the desired torque by {worst} N·m");
}
