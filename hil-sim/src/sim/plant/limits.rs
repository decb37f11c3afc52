//! Size limits of a simulation, checked from the numbers before anything is allocated or
//! run: the work and memory of a run follow from them (control steps = duration × control
//! rate, plant sub-steps = duration × PWM rate × sub-steps, play operators each sub-step).

use thiserror::Error;

use super::ClutchParams;

/// Most play operators of the magnetic hysteresis (`clutch.magnetic.n_play`).
pub const MAX_PLAYS: usize = 256;
/// Most sub-steps per PWM period (`clutch.pwm_substeps`).
pub const MAX_SUBSTEPS: usize = 256;
/// Highest PWM rate, Hz (`clutch.coil.pwm_hz`).
pub const MAX_PWM_HZ: f64 = 200_000.0;
/// Most control steps of one run (duration × control rate): 100 s at 10 kHz; a closed-loop
/// run keeps about 120 bytes a step.
pub const MAX_CONTROL_STEPS: f64 = 1e6;
/// Most plant sub-steps of one run (duration × PWM rate × sub-steps): 300 s of the
/// reference clutch (20 kHz, 16 sub-steps).
pub const MAX_PLANT_SUBSTEPS: f64 = 1e8;

/// Absolute zero, °C: no temperature below it.
pub const ABSOLUTE_ZERO_C: f64 = -273.15;
/// Hottest ambient or initial temperature, °C (the fluid's carrier oil boils off well below).
pub const MAX_TEMPERATURE_C: f64 = 500.0;
/// Narrowest and widest fluid gap, m (MR clutches: 0.1–2 mm; 10 µm is already a bearing fit).
pub const GAP_RANGE_M: (f64, f64) = (10e-6, 10e-3);

/// A number over its limit (or not a number).
#[derive(Clone, Debug, Error, PartialEq)]
#[error("{field} = {}: {limit}", crate::numerics::shown(*value))]
pub struct LimitError {
    pub field: &'static str,
    pub value: f64,
    pub limit: String,
}

fn over(field: &'static str, value: f64, limit: String) -> Result<(), LimitError> {
    Err(LimitError { field, value, limit })
}

impl ClutchParams {
    /// The sizes of the clutch's own numbers ([`MAX_PLAYS`], [`MAX_SUBSTEPS`], [`MAX_PWM_HZ`]).
    pub fn check_sizes(&self) -> Result<(), LimitError> {
        if self.magnetic.n_play > MAX_PLAYS {
            return over("clutch.magnetic.n_play", self.magnetic.n_play as f64, format!("at most {MAX_PLAYS}"));
        }
        if self.pwm_substeps > MAX_SUBSTEPS {
            return over("clutch.pwm_substeps", self.pwm_substeps as f64, format!("at most {MAX_SUBSTEPS}"));
        }
        let hz = self.coil.pwm_hz;
        if !(hz.is_finite() && hz > 0.0 && hz <= MAX_PWM_HZ) {
            return over("clutch.coil.pwm_hz", hz, format!("must be above 0 and at most {MAX_PWM_HZ} Hz"));
        }
        Ok(())
    }

    /// Physical ranges: temperatures above absolute zero (and below
    /// [`MAX_TEMPERATURE_C`]), a gap within [`GAP_RANGE_M`].
    pub fn check_physical(&self) -> Result<(), LimitError> {
        for (field, v) in [("clutch.ambient_c", self.ambient_c), ("clutch.initial_c", self.initial_c)] {
            if !(v > ABSOLUTE_ZERO_C && v <= MAX_TEMPERATURE_C) {
                return over(
                    field,
                    v,
                    format!("a temperature must lie above {ABSOLUTE_ZERO_C} °C and at most {MAX_TEMPERATURE_C} °C"),
                );
            }
        }
        let (lo, hi) = GAP_RANGE_M;
        if !(self.fluid.gap >= lo && self.fluid.gap <= hi) {
            return over("clutch.fluid.gap", self.fluid.gap, format!("the gap must lie within {lo:e} … {hi:e} m"));
        }
        Ok(())
    }

    /// The work of a run of `duration_s` seconds at `control_hz`: at most
    /// [`MAX_CONTROL_STEPS`] control steps and [`MAX_PLANT_SUBSTEPS`] plant sub-steps.
    pub fn check_run(&self, duration_s: f64, control_hz: f64) -> Result<(), LimitError> {
        self.check_sizes()?;
        let steps = duration_s * control_hz;
        if steps.is_nan() || steps > MAX_CONTROL_STEPS {
            return over(
                "duration_s",
                duration_s,
                format!("{steps:.3e} control steps at {control_hz} Hz, at most {MAX_CONTROL_STEPS:.0e}"),
            );
        }
        let subs = duration_s * self.coil.pwm_hz * self.pwm_substeps.max(1) as f64;
        if subs.is_nan() || subs > MAX_PLANT_SUBSTEPS {
            return over(
                "duration_s",
                duration_s,
                format!("{subs:.3e} plant sub-steps (PWM rate × pwm_substeps), at most {MAX_PLANT_SUBSTEPS:.0e}"),
            );
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_reference_clutch_fits_and_huge_numbers_do_not() {
        let c = ClutchParams::default();
        assert_eq!(c.check_run(90.0, 10_000.0), Ok(()));
        assert_eq!(c.check_run(1e9, 10_000.0).unwrap_err().field, "duration_s");
        assert_eq!(c.check_run(f64::INFINITY, 10_000.0).unwrap_err().field, "duration_s");
        assert_eq!(c.check_run(f64::NAN, 10_000.0).unwrap_err().field, "duration_s");
        let mut big = c.clone();
        big.magnetic.n_play = 100_000_000;
        assert_eq!(big.check_sizes().unwrap_err().field, "clutch.magnetic.n_play");
        let mut cold = c.clone();
        cold.initial_c = -300.0;
        assert_eq!(cold.check_physical().unwrap_err().field, "clutch.initial_c");
        let mut thin = c.clone();
        thin.fluid.gap = 1e-300;
        assert_eq!(thin.check_physical().unwrap_err().field, "clutch.fluid.gap");
        assert_eq!(c.check_physical(), Ok(()));
        let mut big = c;
        big.pwm_substeps = 1 << 40;
        assert_eq!(big.check_sizes().unwrap_err().field, "clutch.pwm_substeps");
    }
}
