//! A fitted parameter set (the JSON `fit --save` writes) as the firmware's configuration
//! page ([`model_core::control::page`]): the same encoder the firmware decodes with.

use std::path::Path;

use anyhow::Context;
use model_core::control::{ConfigImage, ControlConfig, ValidatedConfig};
use model_core::Model;

use crate::io::params_file::ParamsFile;
use crate::models::{visit, RateSpec, Visit};

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
pub fn image(file: &ParamsFile, path: &Path, control: ValidatedConfig) -> anyhow::Result<ConfigImage> {
    let flat = file.flat(path)?;
    let dt = control.get().dt;
    visit(&file.model, Check { params: &flat, dt })
        .with_context(|| format!("{}: unknown model `{}`", path.display(), file.model))?
        .with_context(|| format!("{}: {} parameters rejected at dt = {dt} s", path.display(), file.model))?;
    let rate = match &file.rate {
        Some(r) => crate::models::rate::parse(r).map_err(anyhow::Error::msg)?,
        None => RateSpec::Backward,
    };
    rate.build(dt).with_context(|| format!("{}: rate estimator `{rate:?}` at dt = {dt} s", path.display()))?;
    ConfigImage::new(&file.model, &flat, rate, control).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
}

/// Control settings at `control_hz` from the defaults (`ControlConfig::defaults`).
pub fn default_control(control_hz: f32) -> anyhow::Result<ValidatedConfig> {
    ControlConfig::defaults(1.0 / control_hz).validate().context("default control settings")
}
