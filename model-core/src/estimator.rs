//! Sample in, guarded output out: rate estimation, the model step, and the rule for
//! non-finite or overflowing values.

use crate::error::time_step;
use crate::rate::{RateParams, RateState};
use crate::{Finite, Kin, Model, ParamError, Sample};

/// Status bits of one [`Output`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Flags(pub u8);

impl Flags {
    /// The sample's input, rate or command was NaN or ±Inf: it was ignored.
    pub const NON_FINITE_INPUT: u8 = 1 << 0;
    /// The model produced a non-finite output or state for a finite (but huge) input:
    /// the step was rolled back.
    pub const OVERFLOW: u8 = 1 << 1;

    pub const fn ok(self) -> bool {
        self.0 == 0
    }
    pub const fn contains(self, bit: u8) -> bool {
        self.0 & bit != 0
    }
}

/// One step's result: the model output and why it may be a held value.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Output {
    /// Torque (N·m) or force (N), always finite.
    pub y: f32,
    pub flags: Flags,
}

/// A model with its rate estimator at a fixed time step. Immutable after `new`.
#[derive(Clone, Copy, Debug)]
pub struct Estimator<M: Model> {
    pub model: M,
    pub rate: RateParams,
}

/// Everything that changes from sample to sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EstimatorState<S> {
    pub model: S,
    pub rate: RateState,
    /// Last valid output (held on a rejected sample).
    pub last: f32,
    /// Whether the model state has been initialised from a first valid sample.
    pub started: bool,
    /// Count of rejected samples (saturating).
    pub rejected: u32,
}

impl<M: Model> Estimator<M> {
    /// Pair a model with a rate estimator. Both must have been built for the same `dt`.
    pub fn new(model: M, rate: RateParams) -> Result<Self, ParamError> {
        time_step(model.dt())?;
        Ok(Self { model, rate })
    }

    /// A fresh state.
    pub fn state(&self) -> EstimatorState<M::State> {
        EstimatorState::default()
    }

    /// Process one sample.
    ///
    /// ```
    /// use model_core::models::lugre::{LuGre, SEED000_AVERAGE};
    /// use model_core::rate::RateParams;
    /// use model_core::{Estimator, Flags, Model, Sample};
    ///
    /// let dt = 1e-4;
    /// let est = Estimator::new(LuGre::from_params(&SEED000_AVERAGE, dt)?, RateParams::backward(dt)?)?;
    /// let mut state = est.state();
    /// let out = est.step(&mut state, Sample::new(1.5));
    /// assert!(out.flags.ok() && out.y.is_finite());
    /// // A NaN sample changes nothing and holds the output.
    /// let held = est.step(&mut state, Sample::new(f32::NAN));
    /// assert_eq!(held.y, out.y);
    /// assert!(held.flags.contains(Flags::NON_FINITE_INPUT));
    /// # Ok::<(), model_core::ParamError>(())
    /// ```
    ///
    /// Non-finite rule: a sample whose `x`, `u`, `dx` or `ddx` is NaN or ±Inf is
    /// ignored — no state changes, the output is the last valid output (0 before the
    /// first), and [`Flags::NON_FINITE_INPUT`] is set. A finite sample that drives the
    /// rate estimate, the model state or the output to a non-finite value (a huge input)
    /// is rolled back the same way with [`Flags::OVERFLOW`]. The output is therefore
    /// always finite and the state always the last good one.
    #[inline]
    pub fn step(&self, s: &mut EstimatorState<M::State>, sample: Sample) -> Output {
        let u = sample.u.unwrap_or(0.0);
        // `0·v` is 0 for a finite v and NaN otherwise: one test for all of them.
        let zero_in = 0.0 * sample.x + 0.0 * u + 0.0 * sample.dx.unwrap_or(0.0) + 0.0 * sample.ddx.unwrap_or(0.0);
        if zero_in != 0.0 {
            return self.reject(s, Flags::NON_FINITE_INPUT);
        }
        self.advance(s, sample.x, sample.dx, sample.ddx, u)
    }

    /// [`step`](Self::step) for a sample of input `x` and command `u` without measured
    /// rates, known to be finite (the control step's ADC counts times validated gains):
    /// the same result without the input test. A non-finite `x` is still rejected (as
    /// [`Flags::OVERFLOW`]: the rate estimate turns non-finite).
    #[inline]
    pub fn step_finite(&self, s: &mut EstimatorState<M::State>, x: f32, u: f32) -> Output {
        self.advance(s, x, None, None, u)
    }

    #[inline(always)]
    fn advance(&self, s: &mut EstimatorState<M::State>, x: f32, dx: Option<f32>, ddx: Option<f32>, u: f32) -> Output {
        // Work on copies and commit only a good step (a rejected one changes nothing).
        let mut rate = s.rate;
        let (edx, eddx) = self.rate.step(&mut rate, x);
        let k = Kin { x, dx: dx.unwrap_or(edx), ddx: ddx.unwrap_or(eddx), u };
        let mut model = if s.started { s.model } else { self.model.initial_state(&k) };
        let y = self.model.step(&mut model, &k);
        // The estimated rates are the estimator's new state (every `RateParams` variant
        // returns what it stores); measured ones were checked on the way in.
        let zero = 0.0 * y + 0.0 * rate.x + 0.0 * rate.dx + 0.0 * rate.ddx;
        if zero != 0.0 || !model.is_finite() {
            return self.reject(s, Flags::OVERFLOW);
        }
        s.rate = rate;
        s.model = model;
        s.started = true;
        s.last = y;
        Output { y, flags: Flags(0) }
    }

    fn reject(&self, s: &mut EstimatorState<M::State>, bit: u8) -> Output {
        s.rejected = s.rejected.saturating_add(1);
        Output { y: s.last, flags: Flags(bit) }
    }
}

#[cfg(test)]
mod tests;
