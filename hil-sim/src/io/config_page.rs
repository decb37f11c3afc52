//! A fitted parameter set (the JSON `fit --save` writes) as the firmware's configuration
//! page ([`model_core::control::page`]): the same encoder the firmware decodes with.

use std::path::{Path, PathBuf};

use model_core::control::{ConfigImage, ControlConfig, PageError, RateSpec, ValidatedConfig};
use model_core::registry::{visit, Visit};
use model_core::{Model, ParamError};
use thiserror::Error;

use crate::io::params_file::{ParamsFile, ParamsFileError};
use crate::io::rate::RateParseError;

/// Why a parameter file does not make a configuration page.
#[derive(Debug, Error)]
pub enum PageBuildError {
    #[error(transparent)]
    File(#[from] ParamsFileError),
    #[error("{}: unknown model `{model}`", path.display())]
    UnknownModel { path: PathBuf, model: String },
    #[error("{}: {model} parameters rejected at dt = {dt} s: {source}", path.display())]
    Params { path: PathBuf, model: String, dt: f32, source: ParamError },
    #[error("{}: `rate` {source}", path.display())]
    RateText { path: PathBuf, source: RateParseError },
    #[error("{}: rate estimator `{rate:?}` at dt = {dt} s: {source}", path.display())]
    Rate { path: PathBuf, rate: RateSpec, dt: f32, source: ParamError },
    #[error("{}: {source}", path.display())]
    Page { path: PathBuf, source: PageError },
    #[error("default control settings at {control_hz} Hz: {source}")]
    Control { control_hz: f32, source: ParamError },
    #[error("model `{model}` runs at {want} Hz on the firmware (`firmware::runner`), not {control_hz} Hz")]
    WrongRate { model: String, control_hz: f32, want: u32 },
    #[error("{}: model `{model}`: the firmware runs only {} ({why})", path.display(), FIRMWARE_MODELS.join(", "))]
    NotInFirmware { path: PathBuf, model: String, why: &'static str },
    #[error("{}: {model} parameters give a torque of {value:.3e} on a representative flux sweep (±{TRIAL_B} T); \
             the firmware's f32 control step cannot use them", path.display())]
    Absurd { path: PathBuf, model: String, value: f32 },
}

/// The models the firmware is built with (`firmware::runner::Loop`): a page for any other
/// model is refused there (`PageError::WrongModel`), so it is refused here.
pub const FIRMWARE_MODELS: [&str; firmware::runner::MODELS.len()] = firmware::runner::MODELS;

/// Peak flux density of the trial sweep, T.
const TRIAL_B: f32 = 1.5;
/// Largest torque (N·m) a parameter set may give on the trial sweep.
const TRIAL_MAX: f32 = 1e6;

/// The firmware's fastest control rate (its PWM frequency), Hz.
pub const CONTROL_HZ: f32 = 20_000.0;

/// The control rate the firmware runs `model` at, Hz (`firmware::runner::control_hz_of`:
/// the fastest of its rates at which the model's control interrupt fits its CPU share);
/// `None` for a model the firmware does not run.
pub fn firmware_control_hz(model: &str) -> Option<u32> {
    firmware::runner::control_hz_of(model)
}

/// The default control settings at the rate the firmware runs `model` at (the page's time
/// step is its period); `requested`, if given, must be that rate. A model the firmware does
/// not run gets [`CONTROL_HZ`] (its page is refused by [`firmware_image`]).
pub fn firmware_control(model: &str, requested: Option<f32>) -> Result<(f32, ValidatedConfig), PageBuildError> {
    let hz = match (firmware_control_hz(model), requested) {
        (Some(want), Some(hz)) if hz != want as f32 => {
            return Err(PageBuildError::WrongRate { model: model.to_owned(), control_hz: hz, want })
        }
        (Some(want), _) => want as f32,
        (None, r) => r.unwrap_or(CONTROL_HZ),
    };
    Ok((hz, default_control(hz)?))
}

struct Check<'a> {
    params: &'a [f32],
    dt: f32,
}

impl Visit for Check<'_> {
    /// Validation, then the largest |output| (or a non-finite one) on the trial sweep.
    type Out = Result<f32, model_core::ParamError>;
    fn visit<M: Model>(self) -> Self::Out {
        let m = M::from_params(self.params, self.dt)?;
        // Two periods of a 5 Hz sine of ±TRIAL_B T, and its rate, at the page's time step.
        let w = 2.0 * core::f32::consts::PI * 5.0;
        let n = ((0.4 / self.dt) as usize).clamp(100, 20_000);
        let kin = |k: usize| {
            let t = k as f32 * 0.4 / n as f32;
            model_core::Kin::new(TRIAL_B * (w * t).sin(), TRIAL_B * w * (w * t).cos(), 0.0, 0.0)
        };
        let mut s = m.initial_state(&kin(0));
        let mut worst = 0.0f32;
        for k in 0..n {
            let y = m.step(&mut s, &kin(k));
            if !y.is_finite() || !model_core::Finite::is_finite(&s) {
                return Ok(f32::NAN);
            }
            worst = worst.max(y.abs());
        }
        Ok(worst)
    }
}

/// The page for `file` (read from `path`) with control settings `control`: the model and
/// its parameters are validated exactly as the firmware will (`from_params` at the
/// settings' time step), the rate estimator is the file's (`rate`, else backward).
pub fn image(file: &ParamsFile, path: &Path, control: ValidatedConfig) -> Result<ConfigImage, PageBuildError> {
    let flat = file.flat(path)?;
    let dt = control.get().dt;
    let (p, model) = (|| path.to_owned(), || file.model.clone());
    let worst = visit(&file.model, Check { params: &flat, dt })
        .ok_or_else(|| PageBuildError::UnknownModel { path: p(), model: model() })?
        .map_err(|source| PageBuildError::Params { path: p(), model: model(), dt, source })?;
    if worst.is_nan() || worst > TRIAL_MAX {
        return Err(PageBuildError::Absurd { path: p(), model: model(), value: worst });
    }
    let rate = match &file.rate {
        Some(r) => crate::io::rate::parse(r).map_err(|source| PageBuildError::RateText { path: p(), source })?,
        None => RateSpec::Backward,
    };
    rate.build(dt).map_err(|source| PageBuildError::Rate { path: p(), rate, dt, source })?;
    ConfigImage::new(&file.model, &flat, rate, control).map_err(|source| PageBuildError::Page { path: p(), source })
}

/// The page for `file` as [`image`] makes it, refused unless the firmware is built with
/// its model ([`FIRMWARE_MODELS`]): what `export` writes.
pub fn firmware_image(file: &ParamsFile, path: &Path, control: ValidatedConfig) -> Result<ConfigImage, PageBuildError> {
    if !FIRMWARE_MODELS.contains(&file.model.as_str()) {
        let why = "this is a damper model, force from displacement and a command, which the clutch board cannot run";
        return Err(PageBuildError::NotInFirmware { path: path.to_owned(), model: file.model.clone(), why });
    }
    image(file, path, control)
}

/// Control settings at `control_hz` from the defaults (`ControlConfig::defaults`).
pub fn default_control(control_hz: f32) -> Result<ValidatedConfig, PageBuildError> {
    ControlConfig::defaults(1.0 / control_hz)
        .validate()
        .map_err(|source| PageBuildError::Control { control_hz, source })
}
