//! The bench's own signal tools, written for it alone (no code shared with the diagnosis):
//! the papers' field excitations, derivatives, first-order lags, a zero-phase Butterworth
//! low-pass and a fractional delay by cubic interpolation.

use std::f64::consts::PI;

use rand::Rng;
use rand_distr::{Distribution, StandardNormal};

/// The excitations of the papers the bench draws from.
pub const EXCITATIONS: &[&str] = &["multisine", "sweep", "blocks", "noise"];

/// One draw of unit white noise.
pub fn gauss(rng: &mut impl Rng) -> f64 {
    StandardNormal.sample(rng)
}

/// Excitation `name` at times `t` (duration `dur`, s), normalised to [−1, 1]:
///
/// - `multisine`: five to seven tones between 0.5 and 12 Hz with random phases (seed 000);
/// - `sweep`: a logarithmic swept sine 0.5 → 12 Hz, swept up and back down so that both
///   halves of the recording see every frequency (seed 002);
/// - `blocks`: blocks of 2–4 s, each a sine of 1 to 9 Hz (whole hertz) with a random
///   amplitude between 0.5 and 1, joined at zero crossings of the sine (seed 001's tests);
/// - `noise`: white noise through a fourth-order low-pass at 4–10 Hz (zero phase), the
///   band-limited random excitation of seed 000.
pub fn excitation(name: &str, t: &[f64], dur: f64, dt: f64, rng: &mut impl Rng) -> Vec<f64> {
    let raw: Vec<f64> = match name {
        "multisine" => {
            let n = rng.random_range(5..=7);
            let tones: Vec<(f64, f64, f64)> = (0..n)
                .map(|_| (rng.random_range(0.5..12.0), rng.random_range(0.0..2.0 * PI), rng.random_range(0.4..1.0)))
                .collect();
            t.iter().map(|t| tones.iter().map(|(f, p, a)| a * (2.0 * PI * f * t + p).sin()).sum()).collect()
        }
        "sweep" => {
            let (f0, f1) = (0.5, rng.random_range(9.0..14.0));
            let half = 0.5 * dur;
            let k: f64 = f1 / f0;
            // Phase of the up-sweep at time s of its half; the down-sweep mirrors it.
            let phase = |s: f64| 2.0 * PI * f0 * half / k.ln() * (k.powf(s / half) - 1.0);
            let top = phase(half);
            t.iter()
                .map(|t| if *t <= half { phase(*t).sin() } else { (2.0 * top - phase(2.0 * half - t)).sin() })
                .collect()
        }
        "blocks" => {
            // A block ends at the first zero crossing of its sine after its 2–4 s: the next
            // starts from phase 0, so the field never jumps (only its slope changes).
            let mut out = Vec::with_capacity(t.len());
            let (mut f, mut a, mut until, mut phase) = (0.0, 0.0, -1.0, 0.0);
            for tk in t {
                let next = phase + 2.0 * PI * f * dt;
                let crossed = (next / PI).floor() > (phase / PI).floor();
                if *tk >= until && (crossed || f == 0.0) {
                    f = f64::from(rng.random_range(1..=9));
                    a = rng.random_range(0.5..1.0);
                    until = tk + rng.random_range(2.0..4.0);
                    phase = 0.0;
                } else {
                    phase = next;
                }
                out.push(a * phase.sin());
            }
            out
        }
        _ => {
            let white: Vec<f64> = t.iter().map(|_| gauss(rng)).collect();
            let fc = rng.random_range(4.0..10.0);
            let once = butter2_zero_phase(&white, fc, dt);
            butter2_zero_phase(&once, fc, dt)
        }
    };
    let peak = raw.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(1e-12);
    raw.iter().map(|v| v / peak).collect()
}

/// Rate of `x` (sample interval `dt`): fourth-order central differences inside, one-sided
/// at the ends.
pub fn derivative(x: &[f64], dt: f64) -> Vec<f64> {
    let n = x.len();
    (0..n)
        .map(|k| {
            if k >= 2 && k + 2 < n {
                (x[k - 2] - 8.0 * x[k - 1] + 8.0 * x[k + 1] - x[k + 2]) / (12.0 * dt)
            } else if k + 1 < n && k > 0 {
                (x[k + 1] - x[k - 1]) / (2.0 * dt)
            } else if k + 1 < n {
                (x[k + 1] - x[k]) / dt
            } else if k > 0 {
                (x[k] - x[k - 1]) / dt
            } else {
                0.0
            }
        })
        .collect()
}

/// First-order lag `τ·ẏ = x − y` by the trapezoidal (Tustin) rule, started at `x[0]`.
pub fn first_order(x: &[f64], tau_s: f64, dt: f64) -> Vec<f64> {
    if tau_s <= 0.0 {
        return x.to_vec();
    }
    let a = (2.0 * tau_s - dt) / (2.0 * tau_s + dt);
    let g = dt / (2.0 * tau_s + dt);
    let mut y = x.first().copied().unwrap_or(0.0);
    let mut prev = y;
    x.iter()
        .map(|v| {
            y = a * y + g * (v + prev);
            prev = *v;
            y
        })
        .collect()
}

/// A second-order Butterworth low-pass (bilinear, corner `fc` Hz) run forward then backward:
/// no phase shift, a fourth-order magnitude roll-off. The ends start at rest on the first
/// sample.
pub fn butter2_zero_phase(x: &[f64], fc: f64, dt: f64) -> Vec<f64> {
    let once = butter2(x, fc, dt);
    let mut rev: Vec<f64> = once.into_iter().rev().collect();
    rev = butter2(&rev, fc, dt);
    rev.reverse();
    rev
}

fn butter2(x: &[f64], fc: f64, dt: f64) -> Vec<f64> {
    let k = (PI * (fc * dt).min(0.45)).tan();
    let q = std::f64::consts::FRAC_1_SQRT_2;
    let norm = 1.0 / (1.0 + k / q + k * k);
    let b0 = k * k * norm;
    let (b1, b2) = (2.0 * b0, b0);
    let a1 = 2.0 * (k * k - 1.0) * norm;
    let a2 = (1.0 - k / q + k * k) * norm;
    let x0 = x.first().copied().unwrap_or(0.0);
    let (mut x1, mut x2, mut y1, mut y2) = (x0, x0, x0, x0);
    x.iter()
        .map(|v| {
            let y = b0 * v + b1 * x1 + b2 * x2 - a1 * y1 - a2 * y2;
            (x2, x1, y2, y1) = (x1, *v, y1, y);
            y
        })
        .collect()
}

/// `x` delayed by `delay_s` (negative: advanced), read between samples by cubic
/// (Catmull–Rom) interpolation; the ends held.
pub fn delayed(x: &[f64], delay_s: f64, dt: f64) -> Vec<f64> {
    let n = x.len();
    if n < 4 {
        return x.to_vec();
    }
    let at = |i: i64| x[i.clamp(0, n as i64 - 1) as usize];
    (0..n)
        .map(|k| {
            let pos = k as f64 - delay_s / dt;
            let i = pos.floor();
            let u = pos - i;
            let i = i as i64;
            let (p0, p1, p2, p3) = (at(i - 1), at(i), at(i + 1), at(i + 2));
            p1 + 0.5 * u * (p2 - p0 + u * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3 + u * (3.0 * (p1 - p2) + p3 - p0)))
        })
        .collect()
}

/// Root-mean-square of `v` about its mean.
pub fn rms_about_mean(v: &[f64]) -> f64 {
    let m = v.iter().sum::<f64>() / v.len().max(1) as f64;
    (v.iter().map(|a| (a - m) * (a - m)).sum::<f64>() / v.len().max(1) as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn filters_and_delays_do_what_they_say() {
        let dt = 1e-3;
        let x: Vec<f64> = (0..4000).map(|k| (2.0 * PI * 3.0 * k as f64 * dt).sin()).collect();
        // The rate of a 3 Hz sine.
        let d = derivative(&x, dt);
        assert!((d[1000] - 2.0 * PI * 3.0 * (2.0 * PI * 3.0).cos()).abs() < 1e-3, "{}", d[1000]);
        // A 2.5-sample delay of a slow sine is the sine 2.5 ms earlier.
        let y = delayed(&x, 2.5e-3, dt);
        assert!((y[1000] - (2.0 * PI * 3.0 * (1.0 - 2.5e-3)).sin()).abs() < 1e-5);
        // Zero phase: a 3 Hz sine through a 100 Hz low-pass comes out in phase.
        let f = butter2_zero_phase(&x, 100.0, dt);
        assert!((f[2000] - x[2000]).abs() < 1e-3);
        // The lag's step response at one time constant: 1 − 1/e.
        let step: Vec<f64> = (0..200).map(|k| if k < 10 { 0.0 } else { 1.0 }).collect();
        let l = first_order(&step, 0.02, dt);
        assert!((l[30] - (1.0 - (-1.0f64).exp())).abs() < 0.02, "{}", l[30]);
    }
}
