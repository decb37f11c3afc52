//! What one sample carries in, and the kinematics a model step sees.

/// One raw sample as the caller has it.
///
/// `x` is the model input: flux density B (mT or T, as the parameters were fitted)
/// for a clutch, displacement for a damper. `u` is the auxiliary command (coil current
/// or driver voltage) for models whose parameters depend on it; `None` means the model
/// sees `u = 0`. `dx`/`ddx` are rates the caller measured; when `None` the
/// [`Estimator`](crate::Estimator)'s rate estimator supplies them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sample {
    pub x: f32,
    pub u: Option<f32>,
    pub dx: Option<f32>,
    pub ddx: Option<f32>,
}

impl Sample {
    /// A sample with only the input.
    pub const fn new(x: f32) -> Self {
        Self { x, u: None, dx: None, ddx: None }
    }
    /// Attach an auxiliary command (current or voltage).
    pub const fn with_command(mut self, u: f32) -> Self {
        self.u = Some(u);
        self
    }
    /// Attach a measured rate of the input.
    pub const fn with_rate(mut self, dx: f32) -> Self {
        self.dx = Some(dx);
        self
    }
}

/// Kinematics handed to [`Model::step`](crate::Model::step): input, its first and second
/// time derivatives (units of x per second, per second squared) and the command.
///
/// The [`Estimator`](crate::Estimator) guarantees every field is finite; a model called
/// directly must be given finite values (it will still not panic otherwise).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Kin {
    pub x: f32,
    pub dx: f32,
    pub ddx: f32,
    pub u: f32,
}

impl Kin {
    pub const fn new(x: f32, dx: f32, ddx: f32, u: f32) -> Self {
        Self { x, dx, ddx, u }
    }
    /// True when every field is finite.
    pub fn is_finite(&self) -> bool {
        self.x.is_finite() && self.dx.is_finite() && self.ddx.is_finite() && self.u.is_finite()
    }
}
