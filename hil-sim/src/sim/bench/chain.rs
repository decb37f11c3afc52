//! The bench's measurement chain and logger: ADCs, noise, and the lab's zero-phase
//! low-pass on the field and the torque (see the module docs of [`super`]).

use std::path::Path;

use rand::Rng;

use super::effects::Applied;
use super::signals::{butter2_zero_phase, gauss};
use super::{Case, World};
use crate::io::recording::{Column, Recording};

/// A sample through a `bits`-bit ADC over ±`full` with `noise_counts` counts of noise.
fn adc(v: f64, full: f64, bits: i32, noise_counts: f64, rng: &mut impl Rng) -> f64 {
    let step = 2.0 * full / f64::from(1 << bits);
    ((v + noise_counts * step * gauss(rng)) / step).round() * step
}

/// The recording of `w` with the effect `a` for case `c` (noise drawn from `rng`).
pub fn record(w: &World, a: &Applied, c: &Case, rng: &mut impl Rng) -> Recording {
    let dt = w.dt;
    let noise = rng.random_range(0.003..0.008) * w.span;
    let fc = rng.random_range(100.0..400.0f64).min(0.2 * c.fs_hz);
    let b_adc: Vec<f64> = a.b_reported.iter().map(|v| adc(*v, 1.0, 12, 0.5, rng)).collect();
    let (lo, hi) = a.torque.iter().fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
    let full = 0.6 * (hi - lo).max(1e-9) + 0.5 * (hi + lo).abs();
    let t_adc: Vec<f64> = a.torque.iter().map(|v| adc(v + noise * gauss(rng), full, 16, 0.0, rng)).collect();
    let i_adc: Vec<f64> = w.i.iter().map(|v| adc(*v, 5.0, 12, 0.5, rng)).collect();
    let speed: Vec<f64> = w.speed.iter().map(|v| v + 0.02 * gauss(rng)).collect();
    let b_rec = butter2_zero_phase(&b_adc, fc, dt);
    let t_rec = butter2_zero_phase(&t_adc, fc, dt);
    let column = |name: &str, v: &[f64]| Column { name: name.to_owned(), values: v.to_vec() };
    let mut columns = vec![
        column("t", &w.t),
        column("b", &b_rec),
        column("torque", &t_rec),
        column("i", &i_adc),
        column("speed", &speed),
    ];
    if c.temperature_channel {
        let temp: Vec<f64> = w.temperature.iter().map(|v| v + 0.05 * gauss(rng)).collect();
        columns.push(column("temperature", &temp));
    }
    Recording::from_columns(Path::new("bench.csv"), columns, Vec::new())
}
