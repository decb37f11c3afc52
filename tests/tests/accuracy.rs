//! Issue acceptance: the f32 one-step-per-sample core stays within 0.5 % R-RMSE of an
//! f64 adaptive-step reference for every ODE model and published parameter set, on the
//! papers' excitations at 500 Hz and 3 kHz and on the real Dyke displacement.

use hil_sim::sim::accuracy::{self, MAX_R_RMSE};

#[test]
fn every_ode_model_meets_the_bound() {
    let path = hil_sim::io::bundled::data_file("dyke/ranran_50.csv").expect("bundled Dyke recording");
    let rec = accuracy::load_dyke(&path).unwrap();
    let rows = accuracy::run_all(None, false, Some(&rec), &hil_sim::progress::NoProgress).unwrap();
    for id in ["bouc_wen", "lugre", "spencer", "dahl", "bouc_wen_asym"] {
        assert!(rows.iter().any(|r| r.model == id), "no accuracy case for {id}");
    }
    assert!(
        rows.iter().any(|r| r.model == "spencer" && r.excitation.contains("ranran_50")),
        "Spencer's published set is not checked on the real recording"
    );
    let bad: Vec<String> = rows
        .iter()
        .filter(|r| !r.pass)
        .map(|r| format!("{} [{}] {} @ {} Hz: {:.4} %", r.model, r.params, r.excitation, r.fs_hz, 100.0 * r.r_rmse))
        .collect();
    assert!(bad.is_empty(), "over {:.1} %: {bad:#?}", 100.0 * MAX_R_RMSE);
}
