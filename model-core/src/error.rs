//! Parameter validation errors. Returned once, when coefficients are built; the
//! step functions themselves cannot fail.

use core::fmt;

/// Why a parameter set was rejected.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamError {
    /// A parameter is NaN or infinite.
    NotFinite { name: &'static str },
    /// A parameter is outside its admissible range `[min, max]` (either may be infinite).
    OutOfRange { name: &'static str, value: f32, min: f32, max: f32 },
    /// A combination of parameters violates a constraint of the paper or of physics.
    Constraint { what: &'static str },
    /// A flat parameter vector has the wrong length.
    WrongCount { expected: usize, got: usize },
    /// The time step is not a finite positive number.
    BadTimeStep { dt: f32 },
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::NotFinite { name } => write!(f, "parameter `{name}` is not finite"),
            Self::OutOfRange { name, value, min, max } => {
                write!(f, "parameter `{name}` = {value} is outside [{min}, {max}]")
            }
            Self::Constraint { what } => write!(f, "parameter constraint violated: {what}"),
            Self::WrongCount { expected, got } => {
                write!(f, "expected {expected} parameters, got {got}")
            }
            Self::BadTimeStep { dt } => write!(f, "time step dt = {dt} s must be finite and > 0"),
        }
    }
}

/// Check that `value` is finite and within `[min, max]`; returns it on success.
pub fn check(name: &'static str, value: f32, min: f32, max: f32) -> Result<f32, ParamError> {
    if !value.is_finite() {
        return Err(ParamError::NotFinite { name });
    }
    if value < min || value > max {
        return Err(ParamError::OutOfRange { name, value, min, max });
    }
    Ok(value)
}

/// Check that `value` is finite (any sign).
pub fn finite(name: &'static str, value: f32) -> Result<f32, ParamError> {
    check(name, value, f32::NEG_INFINITY, f32::INFINITY)
}

/// Check that a time step is finite and strictly positive.
pub fn time_step(dt: f32) -> Result<f32, ParamError> {
    if dt.is_finite() && dt > 0.0 {
        Ok(dt)
    } else {
        Err(ParamError::BadTimeStep { dt })
    }
}

/// Check a flat parameter vector's length.
pub fn count(values: &[f32], expected: usize) -> Result<(), ParamError> {
    if values.len() == expected {
        Ok(())
    } else {
        Err(ParamError::WrongCount { expected, got: values.len() })
    }
}

impl core::error::Error for ParamError {}
