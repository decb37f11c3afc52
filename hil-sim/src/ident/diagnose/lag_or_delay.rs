//! A lag of the field or a late torque, when the held-out tail cannot tell them apart.
//!
//! At a 1–9 Hz excitation a two-pole lag of τ and a delay a little shorter shift the phase
//! alike; what differs is the amplitude the lag takes off the faster components and its
//! phase growing less than linearly with frequency. When both effects' terms come within
//! [`super::replicate::NEAR`] of each other on the tail, the input is given both at once: a
//! delay of a share `s` of the fitted delay, `s` = 0, ¼, ½, ¾, with the lag (of the lag
//! candidate's form) tuned on top and θ refitted, and at `s = 1` the delay alone, tuned. The lag
//! on top of a share may shrink to nothing ([`LAG_FLOOR`]), below the lag candidate's own
//! shortest (one or two samples): what is left of a delay once most of it is given is shorter
//! than that at a low sample rate. The share
//! where the training error is least names the effect: below a half the lag, above it the
//! delay; at a half the profile does not say, and the reversed split decides
//! ([`super::accept`]).

use rayon::prelude::*;
use serde::Serialize;

use super::augment::{Fitted, Problem, Tune};
use super::candidates::Candidate;
use super::rank::Scored;
use super::transform::Transform;

/// Levenberg–Marquardt iterations of each share's refit.
pub const PROFILE_ITERATIONS: usize = 20;
/// The delay's shares of the profile.
pub const SHARES: [f64; 5] = [0.0, 0.25, 0.5, 0.75, 1.0];
/// The shortest lag tuned on top of a share of the delay, as a fraction of the lag
/// candidate's shortest (a fiftieth of a sample or two: no lag at all, `e^−50`).
pub const LAG_FLOOR: f64 = 0.02;

/// The profile over the delay's share.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Mixture {
    /// The fitted delay the shares are taken of, s.
    pub delay_s: f64,
    /// Per share of [`SHARES`]: the lag tuned on top (s; 0 at the last share, which has none)…
    pub lag_s: [f64; 5],
    /// …and the training part's mean squared error relative to the least of them (≥ 1;
    /// infinite, `null` in the JSON, where the refit diverged).
    pub relative_mse: [f64; 5],
    /// The share where the error is least.
    pub best_share: f64,
}

/// Which of the two the profile names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    Lag,
    Delay,
}

impl Mixture {
    /// The effect the least error names; `None` at a half.
    pub fn side(&self) -> Option<Side> {
        if self.best_share < 0.5 {
            Some(Side::Lag)
        } else if self.best_share > 0.5 {
            Some(Side::Delay)
        } else {
            None
        }
    }
}

/// A candidate with its round's refit.
pub type Refitted<'c> = (&'c Candidate, &'c Scored);

/// The profile of the lag `lag` against the delay `delay` (each its candidate and its refit)
/// on top of `reference`; `None` when the delay is not positive (a torque recorded early is
/// no lag) or every refit diverged.
pub fn profile(prob: &Problem<'_>, reference: &Fitted, lag: Refitted<'_>, delay: Refitted<'_>) -> Option<Mixture> {
    let delay_s = delay.1.value;
    if delay_s.is_nan() || delay_s <= 0.0 {
        return None;
    }
    let fits: Vec<(f64, f64)> = SHARES
        .par_iter()
        .map(|&s| {
            let mut transforms = reference.transforms.clone();
            // The last share is the delay alone, tuned as its own refit was (every other share
            // has the lag's time constant free).
            let (c, start, theta) = if s < 1.0 {
                transforms.push(Transform::Delay { delay_s: s * delay_s });
                (lag.0, (1.0 - s) * lag.1.value, &lag.1.fitted.theta)
            } else {
                (delay.0, delay_s, &delay.1.fitted.theta)
            };
            let (lo, hi) = c.bounds();
            let lo = if s < 1.0 { LAG_FLOOR * lo } else { lo };
            let build = |g: f64| {
                let p = (c.build)(g);
                (p.transform, p.terms)
            };
            let tune = Tune { build: &build, start: start.clamp(lo, hi), lo, hi, log: lo > 0.0 };
            let fit = prob.refit(&transforms, &reference.terms, Some(&tune), theta, PROFILE_ITERATIONS);
            let lag_s = if s < 1.0 { fit.as_ref().map_or(0.0, |f| f.1) } else { 0.0 };
            (fit.map_or(f64::INFINITY, |f| f.0.train_mse), lag_s)
        })
        .collect();
    let (k, least) = fits
        .iter()
        .enumerate()
        .filter(|(_, f)| f.0.is_finite())
        .min_by(|a, b| a.1 .0.total_cmp(&b.1 .0))
        .map(|(k, f)| (k, f.0))?;
    let mut lag_s = [0.0; 5];
    let mut relative_mse = [f64::INFINITY; 5];
    for (j, (mse, g)) in fits.iter().enumerate() {
        lag_s[j] = *g;
        relative_mse[j] = mse / least.max(1e-300);
    }
    Some(Mixture { delay_s, lag_s, relative_mse, best_share: SHARES[k] })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ident::dataset::prepare_recording;
    use crate::ident::diagnose::tests::round_one;
    use crate::ident::fit::Dataset;
    use crate::sim::bench::{generate, Case};

    /// A 10 s, 2 kHz multisine recording of the bench's Bouc–Wen clutch (its own generator,
    /// which shares no code with the diagnosis) with `effect` in form `form` at 6 % of the
    /// span.
    fn bench_recording(effect: &str, form: usize, seed: u64) -> Dataset {
        bench_recording_at(2000.0, effect, form, seed)
    }

    fn bench_recording_at(fs_hz: f64, effect: &str, form: usize, seed: u64) -> Dataset {
        let c = Case {
            fs_hz,
            duration_s: 10.0,
            bipolar: false,
            form,
            size: 0.06,
            ..Case::draw(effect, "bouc_wen", "multisine", seed)
        };
        let g = generate(&c).unwrap();
        prepare_recording(g.recording, &Default::default(), 0.7, false).unwrap().data
    }

    /// The profile of round 1's two-pole lag against its delay, on a Bouc–Wen base fitted to
    /// `data`.
    fn profiled(data: &Dataset) -> Mixture {
        round_one(data, |prob, cands, reference, ranked| {
            let pick = |label: &str| {
                let k = cands.iter().position(|c| c.label.starts_with(label)).unwrap();
                (&cands[k], ranked.iter().find(|s| s.index == k).unwrap())
            };
            profile(prob, reference, pick("two-pole lag"), pick("time shift")).unwrap()
        })
    }

    #[test]
    fn a_two_pole_lag_is_told_from_a_delay_and_a_delay_from_it() {
        // The bench's forms: field_lag 1 is the two-pole lag, transport_delay 0 the torque late.
        let lag = profiled(&bench_recording("field_lag", 1, 9_100_001));
        assert_eq!(lag.side(), Some(Side::Lag), "{lag:?}");
        let delay = profiled(&bench_recording("transport_delay", 0, 9_100_002));
        assert_eq!(delay.side(), Some(Side::Delay), "{delay:?}");
        assert!(delay.relative_mse.iter().all(|r| *r >= 1.0) && delay.delay_s > 0.0, "{delay:?}");
    }

    #[test]
    fn what_is_left_of_a_delay_may_be_shorter_than_the_lag_candidates_grid() {
        // At 500 Hz the two-pole lag's grid starts at two samples, 4 ms; a delay of a few
        // milliseconds given three quarters leaves a lag shorter than that to tune on top.
        let data = bench_recording_at(500.0, "transport_delay", 0, 9_100_003);
        let shortest = 2.0 * data.dt;
        let delay = profiled(&data);
        assert!(delay.delay_s > 0.0 && delay.delay_s < 4.0 * shortest, "{delay:?}");
        assert!(delay.lag_s[3] < shortest, "{delay:?}");
        assert_eq!(delay.side(), Some(Side::Delay), "{delay:?}");
    }
}
