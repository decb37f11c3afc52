//! One injected fault, judged: detection time (ms, from the first faulty sample to the end
//! of the step that commands the safe state), latched code against the expected one, and
//! the safe state (PWM off, coil current below 50 mA) at the end of the run.

use model_core::control::{FaultCode, Mode};
use serde::Serialize;

use super::error::LoopError;
use super::harness::{run, Run, T_START};
use super::identify::Identified;
use super::injection::{Injection, Schedule};
use super::references::multisine_reference;
use crate::sim::plant::ClutchParams;

/// Result of one injected fault.
#[derive(Clone, Debug, Serialize)]
pub struct FaultResult {
    pub fault: &'static str,
    pub detected: bool,
    /// From the first faulty sample to the end of the step that commands the safe state, ms.
    pub detect_ms: Option<f64>,
    /// PWM off and coil current below 50 mA at the end of the run.
    pub safe_state: bool,
    pub code: u8,
    pub code_name: &'static str,
    pub expected_code: u8,
    /// Time from detection until the coil current fell below 50 mA, ms.
    pub de_energised_ms: Option<f64>,
    /// A fault latched before the injection (a false trip).
    pub tripped_before_injection: bool,
}

/// Inject `inj` alone at 0.3 s into a multisine torque run and report.
pub fn fault_run(
    id: &Identified,
    clutch: &ClutchParams,
    inj: Injection,
    seed: u64,
) -> Result<(FaultResult, Run), LoopError> {
    let dt = f64::from(id.dt);
    let at = T_START + 0.3;
    let cfg = id.loop_config(0.0)?;
    // The model is first called on the first running sample, after the init sample and the calibration.
    let first_model_sample = 1 + cfg.get().calib_samples as u32;
    // First sample index whose time is ≥ `at`, computed as `run` does.
    let k_at = (0u32..).find(|&k| f64::from(k) * dt >= at).unwrap_or(0);
    let nan_after = if inj == Injection::ModelNan { k_at.saturating_sub(first_model_sample) } else { u32::MAX };
    let step = id.loop_step(nan_after)?;
    let reference = multisine_reference();
    let r = run(clutch, &step, cfg, &reference, at + 0.1, seed, Some(Schedule { injection: inj, at }));
    let k_inj = r.after(at);
    let tripped_before_injection = r.fault[..k_inj].iter().any(|c| *c != 0);
    let k_det = r.fault[k_inj..].iter().position(|c| *c != 0).map(|p| p + k_inj);
    let code = k_det.map_or(0, |k| r.fault[k]);
    let de_energised_ms =
        k_det.and_then(|kd| r.coil_current[kd..].iter().position(|i| i.abs() < 0.05).map(|p| p as f64 * dt * 1e3));
    let end_ok = r.pwm_enable.last() == Some(&false) && r.coil_current.last().is_some_and(|i| i.abs() < 0.05);
    let name =
        |c: u8| Injection::ALL.iter().map(|i| i.expected()).find(|f| f.code() == c).map_or("none", FaultCode::name);
    let res = FaultResult {
        fault: inj.name(),
        detected: k_det.is_some(),
        detect_ms: k_det.map(|k| (k - k_inj + 1) as f64 * dt * 1e3),
        safe_state: end_ok,
        code,
        code_name: if code == 0 { "none" } else { name(code) },
        expected_code: inj.expected().code(),
        de_energised_ms,
        tripped_before_injection,
    };
    Ok((res, r))
}

/// Whether a mode is the latched fault state.
pub fn is_fault(m: Mode) -> bool {
    matches!(m, Mode::Fault(_))
}
