//! The input's rate and acceleration for offline work (the diagnosis), without the phase
//! lag of a causal estimator.
//!
//! The firmware's estimators ([`crate::models::RateSpec`]) are causal, so their rate
//! lags the true one; a base model fitted through them carries that lag, and a diagnosis
//! would report it as a `field_lag` of the clutch. Offline the whole recording is known:
//! here the input is low-passed forward and backward (a first-order filter at
//! [`CUTOFF_OF_FS`] of the sampling rate, run both ways: zero phase, |H|² attenuation
//! 1/(1 + (f/fc)²), 1 % at fc/7) and differentiated by central differences; the
//! acceleration is the rate treated the same way. The diagnosis smooths at
//! [`content_cutoff`] instead, lower when the input's content ends well below fs/8.

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
    rates_below(x, dt, CUTOFF_OF_FS / dt)
}

/// [`rates`] smoothed at `cutoff_hz` instead (at most [`CUTOFF_OF_FS`] of the sampling rate).
pub fn rates_below(x: &[f64], dt: f64, cutoff_hz: f64) -> (Vec<f64>, Vec<f64>) {
    let share = (cutoff_hz * dt).clamp(1e-6, CUTOFF_OF_FS);
    let tau = 1.0 / (2.0 * std::f64::consts::PI * share);
    let dx = gradient(&filtfilt(x, tau), dt);
    let ddx = gradient(&filtfilt(&dx, tau), dt);
    (dx, ddx)
}

/// The zero-phase rate's cutoff is at least this multiple of [`content_frequency`]: the
/// rate within 1.6 % up to the frequency below which 99.9 % of the input's power lies.
pub const CUTOFF_OF_CONTENT: f64 = 8.0;

/// The cutoff (Hz) of the zero-phase rate for the input `x`: [`CUTOFF_OF_CONTENT`] × its
/// [`content_frequency`], at most [`CUTOFF_OF_FS`] of the sampling rate. A rate wider than
/// the input's content only carries more noise (a 12-bit Hall reading's steps,
/// differentiated), and a steep rate term (`tanh(β·ḃ)`) turns that noise into an error
/// that a lag of the input, which smooths too, then appears to explain.
pub fn content_cutoff(x: &[f64], dt: f64) -> f64 {
    let top = CUTOFF_OF_FS / dt;
    content_frequency(x, dt).map_or(top, |f| (CUTOFF_OF_CONTENT * f).min(top))
}

/// Share of the input's power (about its mean and trend) below [`content_frequency`].
pub const CONTENT_SHARE: f64 = 0.999;

/// The frequency (Hz) below which [`CONTENT_SHARE`] of the power of `x` (mean and linear
/// trend removed, Hann window, one periodogram) lies; `None` for a flat or too short `x`.
pub fn content_frequency(x: &[f64], dt: f64) -> Option<f64> {
    use rustfft::num_complex::Complex;
    let n = x.len();
    if n < 16 || dt.is_nan() || dt <= 0.0 {
        return None;
    }
    let nf = n as f64;
    let (mt, mx) = ((nf - 1.0) / 2.0, crate::numerics::stats::mean(x));
    let (sxy, sxx) = x.iter().enumerate().fold((0.0, 0.0), |(a, b), (i, v)| {
        let d = i as f64 - mt;
        (a + d * (v - mx), b + d * d)
    });
    let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    let mut buf: Vec<Complex<f64>> = x
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let w = 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / (nf - 1.0)).cos();
            Complex::new(w * (v - mx - slope * (i as f64 - mt)), 0.0)
        })
        .collect();
    rustfft::FftPlanner::<f64>::new().plan_fft_forward(n).process(&mut buf);
    let power: Vec<f64> = buf.iter().take(n / 2 + 1).map(|c| c.norm_sqr()).collect();
    let total: f64 = power.iter().sum();
    if !(total > 0.0 && total.is_finite()) {
        return None;
    }
    let mut cum = 0.0;
    let bin = power.iter().position(|p| {
        cum += p;
        cum >= CONTENT_SHARE * total
    })?;
    Some(bin as f64 / (nf * dt))
}

/// Central-difference derivative (one-sided at the ends).
pub fn gradient(v: &[f64], dt: f64) -> Vec<f64> {
    let [first, .., last] = v else { return vec![0.0; v.len()] };
    let (second, before_last) = (v[1], v[v.len() - 2]);
    let mut out = Vec::with_capacity(v.len());
    out.push((second - first) / dt);
    // The inside, as one loop without branches (vectorised).
    let two_dt = 2.0 * dt;
    out.extend(v.iter().zip(&v[2..]).map(|(a, b)| (b - a) / two_dt));
    out.push((last - before_last) / dt);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_gradient_is_central_inside_and_one_sided_at_the_ends() {
        let dt = 0.37;
        // Entry by entry, as written before the loop was vectorised.
        let one_by_one = |v: &[f64]| -> Vec<f64> {
            (0..v.len())
                .map(|i| match (i.checked_sub(1).and_then(|j| v.get(j)), v.get(i + 1)) {
                    (Some(a), Some(b)) => (b - a) / (2.0 * dt),
                    (None, Some(b)) => (b - v[i]) / dt,
                    (Some(a), None) => (v[i] - a) / dt,
                    (None, None) => 0.0,
                })
                .collect()
        };
        let v: Vec<f64> = (0..41).map(|i| (i as f64 * 0.7).sin() * 3.1 + (i * i) as f64 * 1e-3).collect();
        for n in 0..v.len() {
            let got: Vec<u64> = gradient(&v[..n], dt).iter().map(|g| g.to_bits()).collect();
            let want: Vec<u64> = one_by_one(&v[..n]).iter().map(|g| g.to_bits()).collect();
            assert_eq!(got, want, "{n} samples");
        }
    }

    #[test]
    fn the_cutoff_follows_the_content_and_quiets_a_quantised_rate() {
        let dt = 5e-4;
        let two_pi = 2.0 * std::f64::consts::PI;
        let truth = |t: f64| 0.3 * (two_pi * 3.0 * t).sin() + 0.1 * (two_pi * 7.0 * t + 1.0).sin();
        let rate =
            |t: f64| 0.3 * two_pi * 3.0 * (two_pi * 3.0 * t).cos() + 0.7 * two_pi * (two_pi * 7.0 * t + 1.0).cos();
        // A 12-bit reading over ±1 T: steps of 0.49 mT.
        let step = 2.0 / 4096.0;
        let x: Vec<f64> = (0..20_000).map(|i| (truth(i as f64 * dt) / step).round() * step).collect();
        let f = content_frequency(&x, dt).unwrap();
        assert!((7.0..9.0).contains(&f), "content up to {f} Hz");
        let fc = content_cutoff(&x, dt);
        assert!((fc - CUTOFF_OF_CONTENT * f).abs() < 1e-9 && fc < CUTOFF_OF_FS / dt);
        // What the reading's steps add to the rate, at fs/8 and at the content's cutoff.
        let clean: Vec<f64> = (0..20_000).map(|i| truth(i as f64 * dt)).collect();
        let added = |fc: f64| {
            let (q, c) = (rates_below(&x, dt, fc).0, rates_below(&clean, dt, fc).0);
            ((2000..18_000).map(|i| (q[i] - c[i]).powi(2)).sum::<f64>() / 16_000.0).sqrt()
        };
        let (wide, narrow) = (added(CUTOFF_OF_FS / dt), added(fc));
        assert!(narrow < 0.25 * wide, "quantisation noise {narrow} T/s at {fc} Hz against {wide} T/s at fs/8");
        // Within 2 % of the true rate's amplitude at 7 Hz: no lag, little loss.
        let dx = rates_below(&clean, dt, fc).0;
        let peak = (2000..18_000).map(|i| dx[i].abs()).fold(0.0, f64::max);
        let true_peak = (2000..18_000).map(|i| rate(i as f64 * dt).abs()).fold(0.0, f64::max);
        assert!((peak / true_peak - 1.0).abs() < 0.02, "peak rate {peak} against {true_peak}");
        // White noise has content everywhere: the cutoff stays at fs/8.
        let mut rng = <rand::rngs::StdRng as rand::SeedableRng>::seed_from_u64(3);
        let w: Vec<f64> = (0..4096).map(|_| rand::Rng::random_range(&mut rng, -1.0..1.0)).collect();
        assert_eq!(content_cutoff(&w, dt), CUTOFF_OF_FS / dt);
    }

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
