//! Channel alignment: a transport delay between the input and the output channel of a
//! recording (physics-catalog.md `transport_delay`: ADC pipelines, logger latency, a filter
//! on one channel only).
//!
//! A delay `d` (seconds, fractional samples allowed) means the input channel was recorded
//! `d` late relative to the output: the model is fed `x(t + d)`, read off the recording by
//! linear interpolation between samples (held at the ends). `d < 0` feeds an earlier input.
//! The command channel (current or voltage) has a delay of its own, `d_u`: the drive
//! electronics between a recorded command and the coil add latency that is not the
//! sensors'.

use model_core::Kin;
use thiserror::Error;

/// Largest |delay| the fit searches, in samples (±2.7 ms at the Dyke files' 3 kHz).
pub const MAX_DELAY_SAMPLES: f64 = 8.0;

/// Why delays cannot be applied to a recording.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum DelayError {
    #[error("delay {} s is not a finite number of seconds", crate::numerics::shown(*delay_s))]
    NotFinite { delay_s: f64 },
    #[error("a delay of {} s leaves no sample of the {duration_s} s recording to score", crate::numerics::shown(*delay_s))]
    NothingCovered { delay_s: f64, duration_s: f64 },
}

/// Delays `ds` (samples, sampling step `dt` seconds) that leave at least one of `n` samples
/// [`covered`]: finite, and shorter than the recording.
pub fn check(n: usize, dt: f64, ds: &[f64]) -> Result<(), DelayError> {
    if let Some(d) = ds.iter().find(|d| !d.is_finite()) {
        return Err(DelayError::NotFinite { delay_s: d * dt });
    }
    let (lo, hi) = covered(n, ds);
    if lo >= hi {
        let longest = ds.iter().fold(0.0f64, |a, d| if d.abs() > a.abs() { *d } else { a });
        return Err(DelayError::NothingCovered { delay_s: longest * dt, duration_s: n as f64 * dt });
    }
    Ok(())
}

/// Position `i + d` of `n` samples as (lower index, upper index, weight of the upper one).
fn bracket(i: usize, d: f64, n: usize) -> (usize, usize, f64) {
    let last = n.saturating_sub(1) as f64;
    let pos = (i as f64 + d).clamp(0.0, last);
    let lo = pos.floor();
    let frac = pos - lo;
    let lo = lo as usize;
    (lo, (lo + 1).min(n.saturating_sub(1)), frac)
}

/// The samples `lo..hi` of `n` whose shifted channels (delays `ds`, in samples) all fall
/// inside the recording; outside it a channel is only held at its end value.
pub fn covered(n: usize, ds: &[f64]) -> (usize, usize) {
    let lo = ds.iter().fold(0.0f64, |a, d| a.max(-d)).ceil() as usize;
    let hi = n.saturating_sub(ds.iter().fold(0.0f64, |a, d| a.max(*d)).ceil() as usize);
    (lo.min(hi), hi)
}

/// `x` read `d` samples later (`y[i] = x(i + d)`, linear interpolation, held at the ends).
pub fn shift(x: &[f64], d: f64) -> Vec<f64> {
    if d == 0.0 {
        return x.to_vec();
    }
    let n = x.len();
    (0..n)
        .map(|i| {
            let (lo, hi, f) = bracket(i, d, n);
            match (x.get(lo), x.get(hi)) {
                (Some(a), Some(b)) => a + f * (b - a),
                _ => 0.0,
            }
        })
        .collect()
}

/// The input read `d` samples later and the command (if any) `d_u` samples later: the
/// channels a model fitted with these delays is fed.
pub fn shift_channels(x: &[f64], u: Option<&[f64]>, d: f64, d_u: f64) -> (Vec<f64>, Option<Vec<f64>>) {
    (shift(x, d), u.map(|u| shift(u, d_u)))
}

/// [`shift_kin`] within each run of a dataset (runs start at `starts`): no run reads
/// another's samples.
pub fn shift_kin_runs(kin: &[Kin], d: f64, d_u: f64, starts: &[usize], out: &mut Vec<Kin>) {
    let n = kin.len();
    let bounds: Vec<usize> = starts.iter().copied().filter(|&s| s > 0 && s < n).collect();
    if bounds.is_empty() {
        return shift_kin(kin, d, d_u, out);
    }
    out.clear();
    let mut seg = Vec::new();
    let mut a = 0;
    for b in bounds.into_iter().chain([n]) {
        shift_kin(kin.get(a..b).unwrap_or(&[]), d, d_u, &mut seg);
        out.append(&mut seg);
        a = b;
    }
}

/// `x` shifted by `d` samples within each run (runs start at `starts`).
pub fn shift_runs(x: &[f64], d: f64, starts: &[usize]) -> Vec<f64> {
    let n = x.len();
    let mut out = Vec::with_capacity(n);
    let mut a = 0;
    for b in starts.iter().copied().filter(|&s| s > 0 && s < n).chain([n]) {
        out.extend(shift(x.get(a..b).unwrap_or(&[]), d));
        a = b;
    }
    out
}

/// The kinematics `x, ẋ, ẍ` read `d` samples later and the command `u` read `d_u` samples
/// later. The rate estimators are linear and time-invariant, so this equals (up to the
/// start-up transient and the interpolation) the kinematics of the shifted input; the fit
/// uses it to avoid re-running the estimator for every trial delay.
pub fn shift_kin(kin: &[Kin], d: f64, d_u: f64, out: &mut Vec<Kin>) {
    out.clear();
    let n = kin.len();
    let lerp = |a: f32, b: f32, f: f64| a + (f as f32) * (b - a);
    out.extend((0..n).filter_map(|i| {
        let (lo, hi, f) = bracket(i, d, n);
        let (a, b) = (kin.get(lo)?, kin.get(hi)?);
        let (ulo, uhi, fu) = bracket(i, d_u, n);
        let u = lerp(kin.get(ulo)?.u, kin.get(uhi)?.u, fu);
        Some(Kin::new(lerp(a.x, b.x, f), lerp(a.dx, b.dx, f), lerp(a.ddx, b.ddx, f), u))
    }));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integer_shift_reads_later_samples_and_holds_the_end() {
        let x = [0.0, 1.0, 2.0, 3.0, 4.0];
        assert_eq!(shift(&x, 2.0), vec![2.0, 3.0, 4.0, 4.0, 4.0]);
        assert_eq!(shift(&x, -1.0), vec![0.0, 0.0, 1.0, 2.0, 3.0]);
        assert_eq!(shift(&x, 0.0), x.to_vec());
    }

    #[test]
    fn coverage_leaves_out_the_samples_a_delay_reads_past_the_ends() {
        assert_eq!(covered(100, &[0.0, 0.0]), (0, 100));
        assert_eq!(covered(100, &[2.5, -1.2]), (2, 97));
        assert_eq!(covered(3, &[8.0]), (0, 0));
        assert!(check(3, 1.0, &[8.0]).is_err());
        assert!(check(100, 1e-3, &[1e12, 0.0]).is_err());
        assert!(check(100, 1e-3, &[-5e3, 0.0]).is_err());
        assert!(check(100, 1e-3, &[f64::NAN]).is_err());
        assert_eq!(check(100, 1e-3, &[2.5, -1.2]), Ok(()));
    }

    #[test]
    fn fractional_shift_interpolates() {
        let x = [0.0, 10.0, 20.0, 30.0];
        let y = shift(&x, 0.25);
        assert!((y[0] - 2.5).abs() < 1e-12 && (y[2] - 22.5).abs() < 1e-12, "{y:?}");
        assert_eq!(y[3], 30.0);
    }

    #[test]
    fn kinematics_shift_moves_input_and_command_separately() {
        let kin: Vec<Kin> = (0..4).map(|i| Kin::new(i as f32, 2.0 * i as f32, 0.0, 10.0 + i as f32)).collect();
        let mut out = Vec::new();
        shift_kin(&kin, 1.5, 0.0, &mut out);
        assert_eq!(out.len(), 4);
        assert!((out[0].x - 1.5).abs() < 1e-6 && (out[0].dx - 3.0).abs() < 1e-6);
        assert_eq!(out[0].u, 10.0);
        assert_eq!(out[3].x, 3.0);
        shift_kin(&kin, 0.0, -1.0, &mut out);
        assert_eq!((out[0].u, out[2].u, out[2].x), (10.0, 11.0, 2.0));
    }
}
