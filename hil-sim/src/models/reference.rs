//! The f64 reference of an ODE model: its continuous-time right-hand side, written from the
//! papers (in `models/<id>/reference.rs`) independently of model-core's discretisations. The accuracy check
//! (`hil-sim accuracy`) integrates them with a fine adaptive step and compares the f32
//! one-step-per-sample core against them.

/// The input at one instant: value, first and second time derivatives, command.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Input {
    pub x: f64,
    pub dx: f64,
    pub ddx: f64,
    pub u: f64,
}

/// An ODE model in continuous time, `ṡ = f(s, input)`, `y = g(s, input)`.
pub trait Reference: Send + Sync {
    /// Number of continuous states.
    fn dim(&self) -> usize;
    /// State at the first instant (must match what the f32 core starts from).
    fn init(&self, first: &Input) -> Vec<f64>;
    /// Time derivative of the state.
    fn rhs(&self, s: &[f64], input: &Input, ds: &mut [f64]);
    /// Model output (torque or force).
    fn output(&self, s: &[f64], input: &Input) -> f64;
}

/// How the unit excitation (range about −1…1) is mapped to the model input.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InputScale {
    pub amplitude: f64,
    pub offset: f64,
}

/// The auxiliary command during a synthetic excitation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Command {
    /// `u = 0` (model ignores it or uses its constant parameters).
    None,
    /// A constant command (A or V).
    Constant(f64),
}

/// One model + one published parameter set to check.
pub struct Case {
    /// Model identifier (as in model-core's registry).
    pub model: &'static str,
    /// Which parameter set, with its source (e.g. "seed 000 Table 3 average").
    pub label: String,
    /// Flat parameter vector in the model's `PARAM_NAMES` order.
    pub params: Vec<f32>,
    /// The independent f64 reference built from the same parameters.
    pub reference: Box<dyn Reference>,
    /// Mapping of the unit synthetic excitations onto the input.
    pub scale: InputScale,
    pub command: Command,
    /// Also check on the real displacement `D` (cm) and command `Y` (V) of
    /// `shared/data/dyke/ranran_50.csv` (damper models with parameters in cm and N).
    pub on_dyke_recording: bool,
}

/// Every case of every ODE model, in the registry's order.
pub fn cases() -> Vec<Case> {
    super::HOSTS.iter().flat_map(|h| h.reference_cases()).collect()
}
