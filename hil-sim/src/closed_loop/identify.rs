//! The lab on the simulated clutch: with the current driver ([`current_driver`]) it records
//! a slow 0–3 A triangle for the baseline's static current → torque map `[a0, a1, a2, a3]`
//! (`T = a0 + a1·|i| + a2·i² + a3·|i|³`, N·m) and the B/i slope (T/A), and five sines
//! 1–9 Hz for seed 000's algebraic model (eq. 14, `T = k·B + c·dB/dt + α·|B|·B³ + t0`,
//! linear least squares on Hall B, its rate from the controller's own estimator, and the
//! load-cell torque).

use model_core::control::{ControlConfig, ControlStep, LoopMode, ValidatedConfig};
use model_core::models::algebraic::Algebraic;
use model_core::rate::{RateParams, RateState};
use serde::Serialize;

use super::error::LoopError;
use super::harness::{run, T_START};
use super::injection::NanAfter;
use super::tuning::{current_driver, torque_config, RATE_FC_HZ};
use crate::numerics::lstsq::fit_rows as least_squares;
use crate::numerics::metrics::metrics;
use crate::sim::excitation::Excitation;
use crate::sim::plant::ClutchParams;

/// Controller settings and models identified on one clutch.
#[derive(Clone, Debug, Serialize)]
pub struct Identified {
    /// Algebraic model (seed 000 eq. 14) `[k, c, alpha, t0]`, B in T.
    pub algebraic: [f32; 4],
    /// R-RMSE of the fitted algebraic model on its training data.
    pub algebraic_fit_r_rmse: f64,
    /// Baseline static map `[a0, a1, a2, a3]`.
    pub map: [f32; 4],
    pub map_fit_r_rmse: f64,
    /// Static B/i slope, T/A.
    pub b_per_amp: f32,
    /// Sample period, s.
    pub dt: f32,
    #[serde(skip)]
    pub torque_cfg: ControlConfig,
}

/// The values of a fitted linear model `X·θ` on its rows.
fn fitted<const N: usize>(rows: &[[f64; N]], th: &[f64; N]) -> Vec<f64> {
    rows.iter().map(|x| x.iter().zip(th).map(|(a, b)| a * b).sum()).collect()
}

/// Identify the algebraic model and the baseline map on `clutch` (see module docs).
pub fn identify(clutch: &ClutchParams, control_hz: f64, seed: u64) -> Result<Identified, LoopError> {
    let (drv, cfg) = current_driver(clutch, control_hz)?;
    let dt = cfg.get().dt;
    let err = |m: &str| LoopError::Identify(m.to_owned());
    // Static map: slow triangle 0–3 A, both branches.
    let tri = |t: f64| 1.5 + 1.5 * Excitation::Triangle { f: 0.25 }.at(t - 1.0).x;
    let r = run(clutch, &drv, cfg, &tri, 9.0, seed, None);
    let k0 = r.after(T_START + 1.0);
    let rows: Vec<[f64; 4]> = r.current[k0..].iter().map(|i| [1.0, i.abs(), i * i, i.abs().powi(3)]).collect();
    let map = least_squares(&rows, &r.load_cell[k0..]).ok_or_else(|| err("static map is singular"))?;
    let map_fit_r_rmse = metrics(&r.load_cell[k0..], &fitted(&rows, &map), None).r_rmse;
    let bi: Vec<[f64; 1]> = r.current[k0..].iter().map(|i| [*i]).collect();
    let [b_per_amp] = least_squares(&bi, &r.b[k0..]).ok_or_else(|| err("B/i slope"))?;
    // Algebraic model: seed 000's fitting sines 1–9 Hz, 0–3 A, 2 s each.
    let rate = RateParams::filtered(dt, RATE_FC_HZ)?;
    let (mut rows, mut y) = (Vec::new(), Vec::new());
    for f in [1.0, 3.0, 5.0, 7.0, 9.0] {
        let sine = move |t: f64| 1.5 - 1.5 * (2.0 * std::f64::consts::PI * f * t).cos();
        let r = run(clutch, &drv, cfg, &sine, T_START + 2.5, seed ^ (f as u64), None);
        let mut rs = RateState::default();
        let k0 = r.after(T_START + 0.5);
        for (k, b) in r.b.iter().enumerate() {
            let (db, _) = rate.step(&mut rs, *b as f32);
            if k >= k0 {
                rows.push([*b, f64::from(db), b.abs() * b.powi(3), 1.0]);
                y.push(r.load_cell[k]);
            }
        }
    }
    let th = least_squares(&rows, &y).ok_or_else(|| err("algebraic fit is singular"))?;
    let algebraic_fit_r_rmse = metrics(&y, &fitted(&rows, &th), None).r_rmse;
    let algebraic = th.map(|v| v as f32);
    let b_per_amp = b_per_amp as f32;
    let torque_cfg = torque_config(clutch, dt, algebraic, b_per_amp, map.map(|v| v as f32));
    Ok(Identified { algebraic, algebraic_fit_r_rmse, map: torque_cfg.map, map_fit_r_rmse, b_per_amp, dt, torque_cfg })
}

impl Identified {
    /// The closed-loop controller (algebraic model, optionally NaN-injecting after `nan_after` model steps).
    pub fn loop_step(&self, nan_after: u32) -> Result<ControlStep<NanAfter<Algebraic>>, LoopError> {
        let [k, c, a, t0] = self.algebraic;
        let m = NanAfter { inner: Algebraic::new(k, c, a, t0, self.dt)?, after: nan_after };
        Ok(ControlStep::new(m, RateParams::filtered(self.dt, RATE_FC_HZ)?)?)
    }
    /// Settings of the closed loop (with temperature compensation `temp_coeff`, 1/K).
    pub fn loop_config(&self, temp_coeff: f32) -> Result<ValidatedConfig, LoopError> {
        Ok(ControlConfig { temp_coeff, ..self.torque_cfg }.validate()?)
    }
    /// Settings of the baseline: open-loop current control through the static map.
    pub fn baseline_config(&self) -> Result<ValidatedConfig, LoopError> {
        Ok(ControlConfig { mode: LoopMode::OpenLoopTorque, ..self.torque_cfg }.validate()?)
    }
}
