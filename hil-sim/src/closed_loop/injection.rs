//! Faults injected by `hil-sim loop --scenario faults`: what each one does to the plant or
//! the configuration, the fault code the supervisor should latch, and [`NanAfter`], a model
//! that turns to NaN after a number of steps.

use model_core::control::{FaultCode, ValidatedConfig};
use model_core::{Finite, Kin, Model, ParamError};
use serde::Serialize;

use crate::sim::plant::coil::CoilFault;
use crate::sim::plant::sensors::HallFault;
use crate::sim::plant::{ClutchParams, Plant};

/// A fault injected by `hil-sim loop --scenario faults`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Injection {
    HallOpen,
    HallShort,
    HallStuck,
    HallNoise,
    CoilOpen,
    CoilShort,
    SupplyDroop,
    ConfigCrc,
    ModelNan,
    Overrun,
}

impl Injection {
    pub const ALL: [Self; 10] = [
        Self::HallOpen,
        Self::HallShort,
        Self::HallStuck,
        Self::HallNoise,
        Self::CoilOpen,
        Self::CoilShort,
        Self::SupplyDroop,
        Self::ConfigCrc,
        Self::ModelNan,
        Self::Overrun,
    ];
    pub const fn name(self) -> &'static str {
        match self {
            Self::HallOpen => "hall_open",
            Self::HallShort => "hall_short",
            Self::HallStuck => "hall_stuck",
            Self::HallNoise => "hall_noise",
            Self::CoilOpen => "coil_open",
            Self::CoilShort => "coil_short",
            Self::SupplyDroop => "supply_droop",
            Self::ConfigCrc => "config_crc",
            Self::ModelNan => "model_nan",
            Self::Overrun => "overrun",
        }
    }
    /// The fault code the supervisor should latch.
    pub const fn expected(self) -> FaultCode {
        match self {
            Self::HallOpen => FaultCode::HallOpen,
            Self::HallShort => FaultCode::HallShort,
            Self::HallStuck => FaultCode::HallStuck,
            Self::HallNoise => FaultCode::HallNoise,
            Self::CoilOpen => FaultCode::CoilOpen,
            Self::CoilShort => FaultCode::OverCurrent,
            Self::SupplyDroop => FaultCode::SupplyLow,
            Self::ConfigCrc => FaultCode::ConfigCrc,
            Self::ModelNan => FaultCode::ModelNonFinite,
            Self::Overrun => FaultCode::Overrun,
        }
    }
    /// Put the fault into the plant or the configuration (once, at its time). A NaN from
    /// the model comes from [`NanAfter`], an overrun from the harness; both change nothing here.
    pub fn apply(self, clutch: &ClutchParams, plant: &mut Plant, cfg: &mut ValidatedConfig) {
        match self {
            Self::HallOpen => plant.faults.hall = HallFault::Open,
            Self::HallShort => plant.faults.hall = HallFault::Short,
            Self::HallStuck => plant.faults.hall = HallFault::Stuck(plant.hall_now()),
            Self::HallNoise => plant.faults.hall = HallFault::Noise(300.0),
            Self::CoilOpen => plant.faults.coil = CoilFault::Open,
            Self::CoilShort => plant.faults.coil = CoilFault::Short,
            Self::SupplyDroop => plant.faults.supply_v = Some(0.5 * clutch.coil.supply_v),
            Self::ConfigCrc => cfg.inject_bit_flip(0x2A5),
            Self::ModelNan | Self::Overrun => {}
        }
    }
}

/// Faults scheduled in a run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Schedule {
    pub injection: Injection,
    /// Injection time, s.
    pub at: f64,
}

/// A model that emits NaN from its `after`-th step on (fault injection for "NaN from a
/// model"); otherwise exactly the inner model.
#[derive(Clone, Copy, Debug)]
pub struct NanAfter<M: Model> {
    pub inner: M,
    pub after: u32,
}

/// State of [`NanAfter`]: the inner state and a step counter.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NanState<S> {
    pub inner: S,
    pub steps: u32,
}

impl<S: Finite> Finite for NanState<S> {
    fn is_finite(&self) -> bool {
        self.inner.is_finite()
    }
}

impl<M: Model> Model for NanAfter<M> {
    type State = NanState<M::State>;
    const ID: &'static str = "nan_after";
    const PARAM_NAMES: &'static [&'static str] = M::PARAM_NAMES;
    const N_PARAMS: usize = M::N_PARAMS;
    fn from_params(values: &[f32], dt: f32) -> Result<Self, ParamError> {
        Ok(Self { inner: M::from_params(values, dt)?, after: u32::MAX })
    }
    fn write_params(&self, out: &mut [f32]) -> usize {
        self.inner.write_params(out)
    }
    fn dt(&self) -> f32 {
        self.inner.dt()
    }
    fn step(&self, s: &mut Self::State, k: &Kin) -> f32 {
        s.steps = s.steps.saturating_add(1);
        if s.steps > self.after {
            return f32::NAN;
        }
        self.inner.step(&mut s.inner, k)
    }
}
