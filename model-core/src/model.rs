//! The contract every hysteresis model fulfils.

use crate::{Kin, ParamError};

/// Plain data that can say whether every number in it is finite.
pub trait Finite {
    fn is_finite(&self) -> bool;
}

impl Finite for f32 {
    fn is_finite(&self) -> bool {
        f32::is_finite(*self)
    }
}
impl<const N: usize> Finite for [f32; N] {
    fn is_finite(&self) -> bool {
        self.iter().all(|v| v.is_finite())
    }
}
impl Finite for () {
    fn is_finite(&self) -> bool {
        true
    }
}

/// A validated, immutable parameter set of one model at one fixed time step.
///
/// Implementors are built by a fallible constructor (`new(..)` in the paper's form, or
/// [`Model::from_params`] from a flat vector in [`Model::PARAM_NAMES`] order) that checks
/// every bound once; [`Model::step`] then cannot fail and allocates nothing.
pub trait Model: Copy + core::fmt::Debug + 'static {
    /// Internal state: plain `Copy` data, all zeros (`Default`) at rest.
    type State: Copy + Default + core::fmt::Debug + PartialEq + Finite;

    /// Identifier as in `shared/spec/cli-contract.md` (e.g. `"bouc_wen"`).
    const ID: &'static str;
    /// Parameter names in the order of the flat vector. A block of several values is
    /// written `name[len]` (e.g. `"w_hidden[56]"`).
    const PARAM_NAMES: &'static [&'static str];
    /// Length of the flat parameter vector.
    const N_PARAMS: usize;

    /// Build from a flat parameter vector (order of [`Model::PARAM_NAMES`]) for time step
    /// `dt` seconds, validating every bound.
    fn from_params(values: &[f32], dt: f32) -> Result<Self, ParamError>;

    /// Write the flat parameter vector into `out` (length [`Model::N_PARAMS`]); returns the
    /// number written (fewer if `out` is short).
    fn write_params(&self, out: &mut [f32]) -> usize;

    /// The time step the coefficients were built for, in seconds.
    fn dt(&self) -> f32;

    /// State to start from, given the first sample (default: all zeros).
    fn initial_state(&self, _first: &Kin) -> Self::State {
        Self::State::default()
    }

    /// Advance one sample and return the model output (torque or force).
    ///
    /// ```
    /// use model_core::models::bouc_wen::{BoucWen, SEED000_AVERAGE};
    /// use model_core::{Kin, Model};
    ///
    /// let model = BoucWen::from_params(&SEED000_AVERAGE, 1e-4)?;
    /// let first = Kin::new(1.5, 0.0, 0.0, 0.0);
    /// let mut state = model.initial_state(&first);
    /// // B, Ḃ, B̈ and the command as the rate estimator (or the caller) has them.
    /// let torque = model.step(&mut state, &Kin::new(1.5002, 2.0, 0.0, 0.0));
    /// assert!(torque.is_finite());
    /// # Ok::<(), model_core::ParamError>(())
    /// ```
    ///
    /// Must not panic for any input; must keep the state within its analytic bound.
    /// With finite, moderate inputs the output is finite; the [`Estimator`](crate::Estimator)
    /// guards the rest.
    fn step(&self, state: &mut Self::State, k: &Kin) -> f32;
}

/// Copy `src` into the front of `out`, returning how many were written.
pub fn write_flat(src: &[f32], out: &mut [f32]) -> usize {
    let n = src.len().min(out.len());
    for (o, s) in out.iter_mut().zip(src.iter()) {
        *o = *s;
    }
    n
}

/// The outputs of a bank of `N` operators (play operators, elasto-slide elements, …).
///
/// A named wrapper because `Default` is not implemented for arrays longer than 32.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OperatorStates<const N: usize> {
    pub z: [f32; N],
}

impl<const N: usize> Default for OperatorStates<N> {
    fn default() -> Self {
        Self { z: [0.0; N] }
    }
}

impl<const N: usize> Finite for OperatorStates<N> {
    fn is_finite(&self) -> bool {
        self.z.is_finite()
    }
}
