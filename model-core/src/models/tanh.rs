//! PLACEHOLDER — to be replaced by the real `tanh` model.
use crate::{Kin, Model, ParamError};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placeholder;
pub type State = ();
pub type Registered = Placeholder;

impl Model for Placeholder {
    type State = ();
    const ID: &'static str = "tanh";
    const PARAM_NAMES: &'static [&'static str] = &[];
    const N_PARAMS: usize = 0;
    fn from_params(_v: &[f32], _dt: f32) -> Result<Self, ParamError> {
        Ok(Self)
    }
    fn write_params(&self, _out: &mut [f32]) -> usize {
        0
    }
    fn dt(&self) -> f32 {
        1.0
    }
    fn step(&self, _s: &mut (), _k: &Kin) -> f32 {
        0.0
    }
}
