//! The measurement chain every concealed-effect recording goes through, and the logger:
//!
//! - `b`, `torque`, `i` and `speed` through the lab's first-order 200 Hz anti-alias filter
//!   (the same on every channel, so `none` has no delay between channels);
//! - `b` on a 12-bit ADC over ±1.25 T with 1 count of noise (as [`crate::sim::plant::sensors`]);
//!   `i` on a 12-bit ADC over ±6 A, 1 count;
//! - the torque with white noise of [`NOISE_OF_SPAN`] of its span, then a 16-bit quantiser
//!   over 1.2 × its range;
//! - the speed with 0.01 rad/s and the temperature with 0.1 K of noise;
//! - the logger writes fixed decimals: the time, `b` and the torque to 10⁻⁶, `i` to 10⁻⁵,
//!   the speed to 10⁻⁴, the temperature to 10⁻³.
//!
//! Noise is drawn channel by channel in that order (`b`, torque, `i`, speed, temperature).

use std::f64::consts::PI;
use std::path::Path;

use rand::Rng;
use rand_distr::{Distribution, StandardNormal};

use super::effects::{lag, Concealment};
use super::truth::Truth;
use crate::io::recording::{Column, Recording};

/// Torque noise, fraction of the torque's span (RMS).
pub const NOISE_OF_SPAN: f64 = 0.005;
/// Corner frequency of the anti-alias filter, Hz.
const ANTI_ALIAS_HZ: f64 = 200.0;

/// A sample through a `bits`-bit ADC over ±`full` with `noise_counts` counts of white noise.
fn adc(v: f64, full: f64, bits: i32, noise_counts: f64, rng: &mut impl Rng) -> f64 {
    let step = 2.0 * full / f64::from(1 << bits);
    ((v + noise_counts * step * gauss(rng)) / step).round() * step
}

/// One draw of unit white noise.
fn gauss(rng: &mut impl Rng) -> f64 {
    StandardNormal.sample(rng)
}

/// `v` as the logger writes it, with `decimals` decimals.
fn logged(v: f64, decimals: usize) -> f64 {
    format!("{v:.decimals$}").parse().unwrap_or(v)
}

/// The recording (`t,b,torque,i,speed,temperature`) of `truth` with the effect `effect`
/// through the chain; the torque noise's RMS (N·m) with it.
pub fn record(truth: &Truth, effect: &Concealment, rng: &mut impl Rng) -> (Recording, f64) {
    let dt = truth.dt;
    let lp = |v: &[f64]| lag(v, 1.0 / (2.0 * PI * ANTI_ALIAS_HZ), dt);
    let b_rec: Vec<f64> = lp(&truth.b.iter().map(|v| v + effect.b_offset).collect::<Vec<_>>())
        .into_iter()
        .map(|v| adc(v, 1.25, 12, 1.0, rng))
        .collect();
    let noise = NOISE_OF_SPAN * truth.span;
    let with = &effect.torque;
    let (tlo, thi) = with.iter().fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
    let t_step = 1.2 * (thi - tlo).max(1e-9) / 65536.0;
    let torque_rec: Vec<f64> =
        lp(with).into_iter().map(|v| ((v + noise * gauss(rng)) / t_step).round() * t_step).collect();
    let i_rec: Vec<f64> = lp(&truth.i).into_iter().map(|v| adc(v, 6.0, 12, 1.0, rng)).collect();
    let speed_rec: Vec<f64> = lp(&truth.speed).into_iter().map(|v| v + 0.01 * gauss(rng)).collect();
    let temperature_rec: Vec<f64> = truth.temperature.iter().map(|v| v + 0.1 * gauss(rng)).collect();
    let column = |name: &str, v: &[f64], decimals: usize| Column {
        name: name.to_owned(),
        values: v.iter().map(|v| logged(*v, decimals)).collect(),
    };
    let columns = vec![
        column("t", &truth.t, 6),
        column("b", &b_rec, 6),
        column("torque", &torque_rec, 6),
        column("i", &i_rec, 5),
        column("speed", &speed_rec, 4),
        column("temperature", &temperature_rec, 3),
    ];
    (Recording::from_columns(Path::new("concealed.csv"), columns, Vec::new()), noise)
}
