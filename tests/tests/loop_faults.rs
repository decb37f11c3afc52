//! Closed loop against the simulated clutch: every injected fault is detected within 2 ms
//! (the slow-developing ones — stuck Hall, Hall noise, coil open — judged in the 1 kHz slow
//! pass: within 2 ms plus one slow period plus one sample, 3.1 ms at 10 kHz) and ends in
//! the safe state, and the loop beats the open-loop baseline on the multi-sine by at least
//! 3× in R-RMSE of the true torque.
//!
//! Heavy simulations: run with `cargo test --release -p integration-tests --test loop_faults`.

use hil_sim::closed_loop::{compare, fault_run, identify, multisine_reference, Identified, Injection, T_START};
use hil_sim::sim::plant::ClutchParams;
use std::sync::OnceLock;

fn identified() -> &'static (ClutchParams, Identified) {
    static ID: OnceLock<(ClutchParams, Identified)> = OnceLock::new();
    ID.get_or_init(|| {
        let c = ClutchParams::default();
        let id = identify(&c, 10_000.0, 1).expect("identification");
        (c, id)
    })
}

fn check(inj: Injection) {
    let (c, id) = identified();
    let (f, run) = fault_run(id, c, inj, 3).expect("fault run");
    assert!(!f.tripped_before_injection, "{}: false trip before the injection", f.fault);
    assert!(f.detected, "{}: not detected", f.fault);
    assert_eq!(f.code, inj.expected().code(), "{}: latched {} ({})", f.fault, f.code, f.code_name);
    let ms = f.detect_ms.expect("detection time");
    // The slow-developing checks are judged by the slow pass (every 1 ms here): their
    // documented latency adds one slow period and the tripping sample (0.1 ms at 10 kHz).
    let slow_developing = matches!(inj, Injection::HallStuck | Injection::HallNoise | Injection::CoilOpen);
    let limit = if slow_developing { 2.0 + 1.0 + 0.1 } else { 2.0 };
    assert!(ms > 0.0 && ms <= limit, "{}: detected after {ms} ms (limit {limit} ms)", f.fault);
    assert!(f.safe_state, "{}: not in the safe state at the end", f.fault);
    // The safe state is held from detection on: PWM off on every later sample.
    let k_det = run.fault.iter().position(|c| *c != 0).expect("fault index");
    assert!(run.pwm_enable[k_det + 1..].iter().all(|e| !e), "{}: PWM re-enabled after the trip", f.fault);
    assert!(f.de_energised_ms.is_some_and(|t| t < 50.0), "{}: coil still energised: {:?}", f.fault, f.de_energised_ms);
}

#[test]
fn hall_open() {
    check(Injection::HallOpen);
}
#[test]
fn hall_short() {
    check(Injection::HallShort);
}
#[test]
fn hall_stuck() {
    check(Injection::HallStuck);
}
#[test]
fn hall_noise_burst() {
    check(Injection::HallNoise);
}
#[test]
fn coil_open() {
    check(Injection::CoilOpen);
}
#[test]
fn coil_short_over_current() {
    check(Injection::CoilShort);
}
#[test]
fn supply_droop() {
    check(Injection::SupplyDroop);
}
#[test]
fn config_crc_mismatch() {
    check(Injection::ConfigCrc);
}
#[test]
fn nan_from_the_model() {
    check(Injection::ModelNan);
}
#[test]
fn control_step_overrun() {
    check(Injection::Overrun);
}

#[test]
fn multisine_loop_beats_the_baseline_three_times() {
    let (c, id) = identified();
    let (lp, bl) = compare(id, c, &multisine_reference(), T_START + 6.0, 0.0, 5).expect("runs");
    let (tm, bm) = (lp.tracking(T_START + 0.5), bl.tracking(T_START + 0.5));
    assert!(lp.fault.iter().all(|c| *c == 0) && bl.fault.iter().all(|c| *c == 0), "no fault in a healthy run");
    assert!(tm.r_rmse.is_finite() && bm.r_rmse.is_finite());
    assert!(bm.r_rmse >= 3.0 * tm.r_rmse, "loop R-RMSE {:.4}, baseline {:.4}", tm.r_rmse, bm.r_rmse);
}
