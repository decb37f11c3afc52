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
}

/// The firmware's default control rate, Hz.
pub const CONTROL_HZ: f32 = 20_000.0;

struct Check<'a> {
    params: &'a [f32],
    dt: f32,
}

impl Visit for Check<'_> {
    type Out = Result<(), model_core::ParamError>;
    fn visit<M: Model>(self) -> Self::Out {
        M::from_params(self.params, self.dt).map(|_| ())
    }
}

/// The page for `file` (read from `path`) with control settings `control`: the model and
/// its parameters are validated exactly as the firmware will (`from_params` at the
/// settings' time step), the rate estimator is the file's (`rate`, else backward).
pub fn image(file: &ParamsFile, path: &Path, control: ValidatedConfig) -> Result<ConfigImage, PageBuildError> {
    let flat = file.flat(path)?;
    let dt = control.get().dt;
    let (p, model) = (|| path.to_owned(), || file.model.clone());
    visit(&file.model, Check { params: &flat, dt })
        .ok_or_else(|| PageBuildError::UnknownModel { path: p(), model: model() })?
        .map_err(|source| PageBuildError::Params { path: p(), model: model(), dt, source })?;
    let rate = match &file.rate {
        Some(r) => crate::io::rate::parse(r).map_err(|source| PageBuildError::RateText { path: p(), source })?,
        None => RateSpec::Backward,
    };
    rate.build(dt).map_err(|source| PageBuildError::Rate { path: p(), rate, dt, source })?;
    ConfigImage::new(&file.model, &flat, rate, control).map_err(|source| PageBuildError::Page { path: p(), source })
}

/// Control settings at `control_hz` from the defaults (`ControlConfig::defaults`).
pub fn default_control(control_hz: f32) -> Result<ValidatedConfig, PageBuildError> {
    ControlConfig::defaults(1.0 / control_hz)
        .validate()
        .map_err(|source| PageBuildError::Control { control_hz, source })
}
