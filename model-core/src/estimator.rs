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
    /// Non-finite rule: a sample whose `x`, `u`, `dx` or `ddx` is NaN or ±Inf is
    /// ignored — no state changes, the output is the last valid output (0 before the
    /// first), and [`Flags::NON_FINITE_INPUT`] is set. A finite sample that drives the
    /// rate estimate, the model state or the output to a non-finite value (a huge input)
    /// is rolled back the same way with [`Flags::OVERFLOW`]. The output is therefore
    /// always finite and the state always the last good one.
    #[inline]
    pub fn step(&self, s: &mut EstimatorState<M::State>, sample: Sample) -> Output {
        let u = sample.u.unwrap_or(0.0);
        let finite_in = sample.x.is_finite()
            && u.is_finite()
            && sample.dx.is_none_or(f32::is_finite)
            && sample.ddx.is_none_or(f32::is_finite);
        if !finite_in {
            return self.reject(s, Flags::NON_FINITE_INPUT);
        }
        let saved = *s;
        let (edx, eddx) = self.rate.step(&mut s.rate, sample.x);
        let k = Kin {
            x: sample.x,
            dx: sample.dx.unwrap_or(edx),
            ddx: sample.ddx.unwrap_or(eddx),
            u,
        };
        if !k.is_finite() || !s.rate.is_finite() {
            *s = saved;
            return self.reject(s, Flags::OVERFLOW);
        }
        if !s.started {
            s.model = self.model.initial_state(&k);
            s.started = true;
        }
        let y = self.model.step(&mut s.model, &k);
        if !y.is_finite() || !s.model.is_finite() {
            *s = saved;
            return self.reject(s, Flags::OVERFLOW);
        }
        s.last = y;
        Output { y, flags: Flags(0) }
    }

    fn reject(&self, s: &mut EstimatorState<M::State>, bit: u8) -> Output {
        s.rejected = s.rejected.saturating_add(1);
        Output { y: s.last, flags: Flags(bit) }
    }
}
