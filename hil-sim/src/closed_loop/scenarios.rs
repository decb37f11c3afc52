//! The `loop` scenarios as one call: identify the clutch, run the closed loop and the
//! open-loop baseline on the scenario's reference, and gather the tracking metrics (true
//! torque against the reference from [`T_START`] + 0.5 s on) and the scenario's figures.

use serde::Serialize;

use super::error::LoopError;
use super::faults::{fault_run, FaultResult};
use super::frequency_response::{bandwidth, frequency_response, GainPoint};
use super::harness::{run, Run, T_START};
use super::heating::{heating_windows, HeatingWindow};
use super::identify::{identify, Identified};
use super::injection::Injection;
use super::references::{multisine_reference, sine_reference, steps_reference, STEP_S};
use super::step_response::{step_rises, StepRise};
use crate::numerics::metrics::Metrics;
use crate::progress::Progress;
use crate::sim::plant::ClutchParams;

/// A scenario of `hil-sim loop`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LoopScenario {
    /// Torque reference: seed 000 eq. 21 multi-sine mapped to 2–10 N·m.
    Multisine,
    /// Torque steps 2 → 8 → 4 → 10 → 0 → 6 N·m, 0.25 s each.
    Steps,
    /// Stepped sines 2–500 Hz, ±1 N·m around 6 N·m: the −3 dB bandwidth.
    Sweep,
    /// 90 s at 60 rad/s slip, 7 ± 2 N·m at 1 Hz: error drift as the fluid heats.
    Heating,
    /// Each fault injected alone at 0.3 s into a multi-sine run.
    Faults,
}

impl LoopScenario {
    /// Lower-case name (`multisine`, …), as in file names and reports.
    pub const fn name(self) -> &'static str {
        match self {
            Self::Multisine => "multisine",
            Self::Steps => "steps",
            Self::Sweep => "sweep",
            Self::Heating => "heating",
            Self::Faults => "faults",
        }
    }
}

/// What to run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoopSpec {
    pub scenario: LoopScenario,
    /// Control-step rate, Hz.
    pub control_hz: f64,
    /// Duration of the multisine run, s.
    pub duration: f64,
    pub seed: u64,
}

/// Figures particular to a scenario.
#[derive(Clone, Debug)]
pub enum ScenarioFigures {
    Multisine,
    /// 10–90 % rise times at the steps at 0.25, 0.5 and 0.75 s.
    Steps {
        rises: Vec<StepRise>,
    },
    /// −3 dB bandwidths (Hz; `None`: above the last frequency) and the responses.
    Sweep {
        bandwidth_loop: Option<f64>,
        bandwidth_baseline: Option<f64>,
        response_loop: Vec<GainPoint>,
        response_baseline: Vec<GainPoint>,
    },
    /// Nine 10 s windows, the compensated loop's tracking and its run.
    Heating {
        windows: Vec<HeatingWindow>,
        tracking_temp_comp: Metrics,
        temp_comp_run: Box<Run>,
    },
    /// Every injection's result and run, in [`Injection::ALL`]'s order.
    Faults {
        results: Vec<(FaultResult, Run)>,
    },
}

/// A scenario's outcome.
#[derive(Clone, Debug)]
pub struct LoopReport {
    pub scenario: LoopScenario,
    pub identified: Identified,
    pub loop_run: Run,
    pub baseline_run: Run,
    /// Tracking of the true torque against the reference: loop and baseline.
    pub tracking: Metrics,
    pub baseline: Metrics,
    /// Baseline R-RMSE over loop R-RMSE.
    pub improvement_r_rmse: f64,
    pub figures: ScenarioFigures,
}

/// Tracking metrics start this long after the reference, s (past the first transient).
const SETTLE_S: f64 = 0.5;

/// Closed loop and baseline on the same reference: `(loop run, baseline run)`.
pub fn compare(
    id: &Identified,
    clutch: &ClutchParams,
    reference: &dyn Fn(f64) -> f64,
    duration: f64,
    temp_coeff: f32,
    seed: u64,
) -> Result<(Run, Run), LoopError> {
    let step = id.loop_step(u32::MAX)?;
    let lp = run(clutch, &step, id.loop_config(temp_coeff)?, reference, duration, seed, None);
    let bl = run(clutch, &step, id.baseline_config()?, reference, duration, seed, None);
    Ok((lp, bl))
}

impl LoopSpec {
    /// Length of the scenario's longest run, s (the identification runs 9 s).
    pub fn longest_run_s(&self) -> f64 {
        let own = match self.scenario {
            LoopScenario::Multisine => T_START + self.duration,
            LoopScenario::Heating => T_START + 90.0,
            _ => 0.0,
        };
        own.max(9.0)
    }

    /// A rate and a duration that leave samples to score, and runs of `clutch` within
    /// [`crate::sim::plant::limits`].
    pub fn check(&self, clutch: &ClutchParams) -> Result<(), LoopError> {
        let spec = |field, value, reason| Err(LoopError::Spec { field, value, reason });
        if !(self.control_hz.is_finite() && self.control_hz > 0.0) {
            return spec("control_hz", self.control_hz, "the control rate must be a finite number of Hz above 0");
        }
        if !(self.duration.is_finite() && self.duration > SETTLE_S) {
            return spec(
                "duration",
                self.duration,
                "must be a finite number of seconds above 0.5 (the first 0.5 s are not scored)",
            );
        }
        clutch.check_run(self.longest_run_s(), self.control_hz).map_err(|mut e| {
            if e.field == "duration_s" && self.scenario == LoopScenario::Multisine {
                (e.field, e.value) = ("duration", self.duration);
            }
            LoopError::Limit(e)
        })
    }
}

/// Identify `clutch` and run `spec`'s scenario (see [`LoopScenario`]).
pub fn evaluate(clutch: &ClutchParams, spec: &LoopSpec, progress: &dyn Progress) -> Result<LoopReport, LoopError> {
    spec.check(clutch)?;
    progress.stage("identify", 3);
    let id = identify(clutch, spec.control_hz, spec.seed).map_err(|e| LoopError::Identifying(Box::new(e)))?;
    progress.advance(1);
    progress.stage(spec.scenario.name(), 0);
    let seed = spec.seed;
    let ((lp, bl), figures) = match spec.scenario {
        LoopScenario::Multisine => (
            compare(&id, clutch, &multisine_reference(), T_START + spec.duration, 0.0, seed)?,
            ScenarioFigures::Multisine,
        ),
        LoopScenario::Steps => {
            let (lp, bl) = compare(&id, clutch, &steps_reference, T_START + 1.5, 0.0, seed)?;
            let rises = step_rises(&lp, &bl, T_START, STEP_S, 1..4);
            ((lp, bl), ScenarioFigures::Steps { rises })
        }
        LoopScenario::Sweep => sweep(&id, clutch, seed)?,
        LoopScenario::Heating => heating(&id, clutch, seed)?,
        LoopScenario::Faults => {
            let results =
                Injection::ALL.iter().map(|&inj| fault_run(&id, clutch, inj, seed)).collect::<Result<_, _>>()?;
            (
                compare(&id, clutch, &multisine_reference(), T_START + 3.0, 0.0, seed)?,
                ScenarioFigures::Faults { results },
            )
        }
    };
    progress.advance(1);
    let from = T_START + SETTLE_S;
    let (tracking, baseline) = (lp.tracking(from), bl.tracking(from));
    let improvement_r_rmse = baseline.r_rmse / tracking.r_rmse;
    Ok(LoopReport {
        scenario: spec.scenario,
        identified: id,
        loop_run: lp,
        baseline_run: bl,
        tracking,
        baseline,
        improvement_r_rmse,
        figures,
    })
}

type Outcome = ((Run, Run), ScenarioFigures);

/// Frequency responses at 6 ± 1 N·m, and the tracking of a 5 Hz ±1 N·m sine.
fn sweep(id: &Identified, clutch: &ClutchParams, seed: u64) -> Result<Outcome, LoopError> {
    let step = id.loop_step(u32::MAX)?;
    let response_loop = frequency_response(clutch, &step, id.loop_config(0.0)?, 6.0, 1.0, seed);
    let response_baseline = frequency_response(clutch, &step, id.baseline_config()?, 6.0, 1.0, seed);
    let figures = ScenarioFigures::Sweep {
        bandwidth_loop: bandwidth(&response_loop),
        bandwidth_baseline: bandwidth(&response_baseline),
        response_loop,
        response_baseline,
    };
    Ok((compare(id, clutch, &sine_reference(6.0, 1.0, 5.0), T_START + 2.0, 0.0, seed)?, figures))
}

/// 90 s at 60 rad/s slip on 7 ± 2 N·m at 1 Hz, without and with temperature compensation.
fn heating(id: &Identified, clutch: &ClutchParams, seed: u64) -> Result<Outcome, LoopError> {
    let mut hot = clutch.clone();
    hot.motor.speed = vec![[0.0, 60.0]];
    let sine = sine_reference(7.0, 2.0, 1.0);
    let dur = T_START + 90.0;
    let (lp, bl) = compare(id, &hot, &sine, dur, 0.0, seed)?;
    // Compensated: the fluid datasheet's yield slope (−0.3 %/K) as the estimate's coefficient.
    let (lc, _) = compare(id, &hot, &sine, dur, -0.003, seed)?;
    let from = T_START + SETTLE_S;
    let windows = heating_windows(&lp, &lc, &bl, T_START, from, 10, 9);
    let figures =
        ScenarioFigures::Heating { windows, tracking_temp_comp: lc.tracking(from), temp_comp_run: Box::new(lc) };
    Ok(((lp, bl), figures))
}
