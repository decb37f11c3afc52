//! The input's rate and acceleration for offline work (the diagnosis), without the phase
//! lag of a causal estimator.
//!
//! The firmware's estimators ([`crate::models::RateSpec`]) are causal, so their rate
//! lags the true one; a base model fitted through them carries that lag, and a diagnosis
//! would report it as a `field_lag` of the clutch. Offline the whole recording is known:
//! here the input is low-passed forward and backward (a first-order filter at
//! [`CUTOFF_OF_FS`] of the sampling rate, run both ways: zero phase, |H|² attenuation
//! 1/(1 + (f/fc)²), 1 % at fc/7) and differentiated by central differences; the
//! acceleration is the rate treated the same way.

/// Cutoff of the zero-phase smoothing, fraction of the sampling rate (250 Hz at 2 kHz,
/// 375 Hz on the Dyke files' 3 kHz): the rate is within 1 % up to fs/80.
pub const CUTOFF_OF_FS: f64 = 1.0 / 8.0;

/// A first-order low-pass (time constant `tau` samples) run forward then backward.
pub fn filtfilt(v: &[f64], tau_samples: f64) -> Vec<f64> {
    let a = (-1.0 / tau_samples.max(1e-9)).exp();
    let mut out = Vec::with_capacity(v.len());
    let mut f = v.first().copied().unwrap_or(0.0);
    for x in v {
        f = a * f + (1.0 - a) * x;
        out.push(f);
    }
    let mut f = out.last().copied().unwrap_or(0.0);
    for y in out.iter_mut().rev() {
        f = a * f + (1.0 - a) * *y;
        *y = f;
    }
    out
}

/// Zero-phase rate and acceleration of `x` sampled every `dt` seconds.
pub fn rates(x: &[f64], dt: f64) -> (Vec<f64>, Vec<f64>) {
    let tau = 1.0 / (2.0 * std::f64::consts::PI * CUTOFF_OF_FS);
    let dx = gradient(&filtfilt(x, tau), dt);
    let ddx = gradient(&filtfilt(&dx, tau), dt);
    (dx, ddx)
}

/// Central-difference derivative (one-sided at the ends).
pub fn gradient(v: &[f64], dt: f64) -> Vec<f64> {
    let n = v.len();
    (0..n)
        .map(|i| match (i.checked_sub(1).and_then(|j| v.get(j)), v.get(i + 1)) {
            (Some(a), Some(b)) => (b - a) / (2.0 * dt),
            (None, Some(b)) => (b - v[i]) / dt,
            (Some(a), None) => (v[i] - a) / dt,
            (None, None) => 0.0,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sine_rate_has_no_lag_and_its_amplitude() {
        let dt = 5e-4;
        let w = 2.0 * std::f64::consts::PI * 10.0;
        let x: Vec<f64> = (0..8000).map(|i| (w * i as f64 * dt).sin()).collect();
        let (dx, ddx) = rates(&x, dt);
        for i in 2000..6000 {
            let t = i as f64 * dt;
            assert!((dx[i] - w * (w * t).cos()).abs() < 0.02 * w, "rate at {t}: {} vs {}", dx[i], w * (w * t).cos());
            assert!((ddx[i] + w * w * (w * t).sin()).abs() < 0.03 * w * w, "acceleration at {t}");
        }
    }
}
