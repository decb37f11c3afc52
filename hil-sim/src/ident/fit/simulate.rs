//! The model-core step, driven by the optimisers: a flat `f64` parameter vector in, the
//! model's f32 output over a run of precomputed kinematics out.
//!
//! The kinematics (`x, ẋ, ẍ, u`) come from the same rate estimator the firmware runs
//! ([`kinematics`]); they do not depend on the parameters, so they are computed once per fit.

use std::marker::PhantomData;

use model_core::rate::RateState;
use model_core::{Kin, Model, Sample};

use crate::models::{visit, RateSpec, Visit};

/// Runs one model type, chosen at run time by id.
pub trait Simulator: Send + Sync {
    fn id(&self) -> &'static str;
    fn n_params(&self) -> usize;
    /// Whether `p` is a valid parameter set (the model's own constructor decides).
    fn valid(&self, p: &[f64]) -> bool;
    /// Run from rest over `kin`, writing one output per sample into `out` (every sample up to
    /// the shorter of the two: the objective reuses `out` without clearing it). `false` when the
    /// parameters are invalid or the output stops being finite. The state restarts at every
    /// run start ([`Simulator::run_starts`]).
    fn run(&self, p: &[f64], kin: &[Kin], out: &mut [f64]) -> bool;
    /// Where the runs of a dataset start (sample indices); empty or `[0]` for one recording.
    fn run_starts(&self) -> &[usize] {
        &[]
    }
}

struct Sim<M> {
    dt: f32,
    /// Run starts after the first (the state restarts there).
    starts: Vec<usize>,
    _m: PhantomData<fn() -> M>,
}

fn to_f32(p: &[f64]) -> Vec<f32> {
    p.iter().map(|v| *v as f32).collect()
}

impl<M: Model> Simulator for Sim<M> {
    fn id(&self) -> &'static str {
        M::ID
    }
    fn n_params(&self) -> usize {
        M::N_PARAMS
    }
    fn valid(&self, p: &[f64]) -> bool {
        M::from_params(&to_f32(p), self.dt).is_ok()
    }
    fn run(&self, p: &[f64], kin: &[Kin], out: &mut [f64]) -> bool {
        let Ok(model) = M::from_params(&to_f32(p), self.dt) else { return false };
        let n = kin.len().min(out.len());
        let mut a = 0;
        for b in self.starts.iter().copied().filter(|&s| s > 0 && s < n).chain([n]) {
            let (Some(seg), Some(o)) = (kin.get(a..b), out.get_mut(a..b)) else { return false };
            let Some(first) = seg.first() else { continue };
            let mut st = model.initial_state(first);
            for (k, o) in seg.iter().zip(o.iter_mut()) {
                let y = model.step(&mut st, k);
                if !y.is_finite() {
                    return false;
                }
                *o = f64::from(y);
            }
            a = b;
        }
        true
    }
    fn run_starts(&self) -> &[usize] {
        &self.starts
    }
}

struct Make(f32, Vec<usize>);
impl Visit for Make {
    type Out = Box<dyn Simulator>;
    fn visit<M: Model>(self) -> Box<dyn Simulator> {
        Box::new(Sim::<M> { dt: self.0, starts: self.1, _m: PhantomData })
    }
}

/// The simulator of model `id` at step `dt` seconds; `None` for an unknown id.
pub fn simulator(id: &str, dt: f32) -> Option<Box<dyn Simulator>> {
    visit(id, Make(dt, Vec::new()))
}

/// [`simulator`] for a dataset whose runs start at `starts` (sample indices): the state
/// restarts at each.
pub fn simulator_runs(id: &str, dt: f32, starts: &[usize]) -> Option<Box<dyn Simulator>> {
    visit(id, Make(dt, starts.to_vec()))
}

/// The simulator of a model type that is not in the registry (e.g. a smaller size of a
/// const-generic model, trained before it is written into the registered size).
pub fn simulator_of<M: Model>(dt: f32) -> Box<dyn Simulator> {
    Box::new(Sim::<M> { dt, starts: Vec::new(), _m: PhantomData })
}

/// The kinematics the core sees for each sample, from the rate estimator `rate` exactly as
/// [`model_core::Estimator::step`] computes them (a measured rate in the sample wins).
/// `None` if the estimate overflows (the inputs are checked finite before).
pub fn kinematics(samples: &[Sample], dt: f32, rate: RateSpec) -> Option<Vec<Kin>> {
    kinematics_runs(samples, dt, rate, &[])
}

/// [`kinematics`] with the estimator restarted at every run start in `starts`.
pub fn kinematics_runs(samples: &[Sample], dt: f32, rate: RateSpec, starts: &[usize]) -> Option<Vec<Kin>> {
    kinematics_of(samples.iter().copied(), dt, rate, starts)
}

/// [`kinematics_runs`] of samples made as they are needed (a dataset's channels, without
/// holding a sample per row).
pub fn kinematics_of(
    samples: impl Iterator<Item = Sample> + Clone,
    dt: f32,
    rate: RateSpec,
    starts: &[usize],
) -> Option<Vec<Kin>> {
    let params = rate.build(dt).ok()?;
    // Every sample carries both rates (the zero-phase ones): the estimator's would be unused.
    let given = samples.clone().all(|s| s.dx.is_some() && s.ddx.is_some());
    let mut st = RateState::default();
    let mut out = Vec::with_capacity(samples.size_hint().0);
    for (i, s) in samples.enumerate() {
        if i > 0 && starts.contains(&i) {
            st = RateState::default();
        }
        let (dx, ddx) = if given { (0.0, 0.0) } else { params.step(&mut st, s.x) };
        let k = Kin { x: s.x, dx: s.dx.unwrap_or(dx), ddx: s.ddx.unwrap_or(ddx), u: s.u.unwrap_or(0.0) };
        if !k.is_finite() {
            return None;
        }
        out.push(k);
    }
    Some(out)
}

/// [`kinematics`] of the samples [`crate::models::replay::samples_with_rates`] makes of the
/// input `x`, the command `u` and rates of `x`'s length, without making them: every sample
/// carries both rates, so the estimator's are unused (it is still built, as there). The
/// same values to the bit; `None` where [`kinematics`] gives `None`.
pub fn kinematics_given(
    x: &[f64],
    u: Option<&[f64]>,
    dx: &[f64],
    ddx: &[f64],
    dt: f32,
    rate: RateSpec,
) -> Option<Vec<Kin>> {
    rate.build(dt).ok()?;
    if dx.len() != x.len() || ddx.len() != x.len() {
        let rates = (dx.to_vec(), ddx.to_vec());
        return kinematics(&crate::models::replay::samples_with_rates(x, u, Some(&rates)), dt, rate);
    }
    let mut out = Vec::with_capacity(x.len());
    for (i, ((x, dx), ddx)) in x.iter().zip(dx).zip(ddx).enumerate() {
        let u = u.and_then(|u| u.get(i)).map_or(0.0, |u| *u as f32);
        let k = Kin { x: *x as f32, dx: *dx as f32, ddx: *ddx as f32, u };
        if !k.is_finite() {
            return None;
        }
        out.push(k);
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::replay;

    #[test]
    fn given_rates_make_the_kinematics_of_their_samples_to_the_bit() {
        let x: Vec<f64> = (0..300).map(|i| (i as f64 * 0.031).sin() * 1.7 + 1e-9 * i as f64).collect();
        let (dx, ddx) = crate::numerics::derivative::rates(&x, 1e-3);
        let u: Vec<f64> = (0..250).map(|i| 0.01 * i as f64).collect();
        let rates = (dx.clone(), ddx.clone());
        for rate in [RateSpec::Backward, RateSpec::Kalman { q: 1e6, r: 1e-6 }] {
            for u in [None, Some(u.as_slice())] {
                let made = kinematics(&replay::samples_with_rates(&x, u, Some(&rates)), 1e-3, rate);
                assert_eq!(kinematics_given(&x, u, &dx, &ddx, 1e-3, rate), made);
                // Rates shorter than the input: the estimator runs on where they end.
                let short = (dx[..200].to_vec(), ddx[..200].to_vec());
                let made = kinematics(&replay::samples_with_rates(&x, u, Some(&short)), 1e-3, rate);
                assert_eq!(kinematics_given(&x, u, &short.0, &short.1, 1e-3, rate), made);
            }
        }
        let mut bad = x.clone();
        bad[7] = f64::NAN;
        assert_eq!(kinematics_given(&bad, None, &dx, &ddx, 1e-3, RateSpec::Backward), None);
        assert_eq!(kinematics_given(&x, None, &dx, &ddx, 0.0, RateSpec::Backward), None);
    }

    #[test]
    fn given_rates_win_and_the_estimator_runs_on_for_the_samples_without() {
        let dt = 1e-3f32;
        let x: Vec<f32> = (0..400).map(|i| (i as f32 * 0.05).sin()).collect();
        let plain: Vec<Sample> = x.iter().map(|v| Sample::new(*v)).collect();
        let with = |s: Sample, i: usize| Sample { dx: Some(i as f32), ddx: Some(-(i as f32)), ..s };
        let all: Vec<Sample> = plain.iter().enumerate().map(|(i, s)| with(*s, i)).collect();
        // Rates on the first half only: the second half's must be the estimator's own.
        let half: Vec<Sample> = plain.iter().enumerate().map(|(i, s)| if i < 200 { with(*s, i) } else { *s }).collect();
        for rate in [RateSpec::Backward, RateSpec::Filtered { fc: 50.0 }] {
            let est = kinematics_runs(&plain, dt, rate, &[150]).unwrap();
            let given = kinematics_runs(&all, dt, rate, &[150]).unwrap();
            let mixed = kinematics_runs(&half, dt, rate, &[150]).unwrap();
            for i in 0..x.len() {
                assert_eq!((given[i].x, given[i].dx, given[i].ddx), (x[i], i as f32, -(i as f32)));
                let want = if i < 200 { given[i] } else { est[i] };
                assert_eq!((mixed[i].dx, mixed[i].ddx), (want.dx, want.ddx), "{i}");
            }
        }
    }

    #[test]
    fn matches_the_estimator_replay() {
        let dt = 1e-3f32;
        let samples: Vec<Sample> = (0..2000)
            .map(|i| {
                let t = i as f32 * dt;
                Sample::new(2.0 * (7.0 * t).sin() + 0.3 * (31.0 * t).sin()).with_command(1.0 + 0.5 * (3.0 * t).sin())
            })
            .collect();
        let spencer = [21.0, 3.5, 46.9, 283.0, 2.95, 5.0, 14.3, 140.0, 695.0, 363.0, 363.0, 301.0, 2.0, 190.0];
        for rate in [RateSpec::Backward, RateSpec::Filtered { fc: 50.0 }] {
            let kin = kinematics(&samples, dt, rate).unwrap();
            let sim = simulator("spencer", dt).unwrap();
            let mut out = vec![0.0; kin.len()];
            let p: Vec<f64> = spencer.iter().map(|v| f64::from(*v)).collect();
            assert!(sim.run(&p, &kin, &mut out));
            let want = replay("spencer", &spencer, dt, rate, &samples).unwrap();
            for (a, b) in out.iter().zip(&want.y) {
                assert_eq!(*a, f64::from(*b));
            }
        }
    }

    #[test]
    fn every_sample_is_written_whatever_the_buffer_held() {
        let dt = 1e-3f32;
        let samples: Vec<Sample> = (0..1500)
            .map(|i| {
                let t = i as f32 * dt;
                Sample::new(0.4 + 0.3 * (5.0 * t).sin()).with_command(1.0 + 0.5 * (3.0 * t).sin())
            })
            .collect();
        let kin = kinematics(&samples, dt, RateSpec::Backward).unwrap();
        let scales = crate::models::search::Scales {
            x_mean: 0.4,
            x: 0.2,
            dx: 1.0,
            ddx: 5.0,
            y_mean: 2.0,
            y: 1.0,
            u: Some(1.5),
            fs: 1000.0,
        };
        let mut ran = 0;
        // Every model of the registry with a search space (the parametric ones and more).
        for id in model_core::registry::MODELS.iter().map(|m| m.id) {
            let (Some(sim), Some(spec)) =
                (simulator_runs(id, dt, &[0, 700]), crate::models::host(id).and_then(|h| h.spec(&scales, None)))
            else {
                continue;
            };
            let p = spec.start();
            let (mut zeros, mut nans) = (vec![0.0; kin.len()], vec![f64::NAN; kin.len()]);
            assert_eq!(sim.run(&p, &kin, &mut zeros), sim.run(&p, &kin, &mut nans), "{id}");
            if sim.run(&p, &kin, &mut nans) {
                assert_eq!(zeros, nans, "{id}");
                ran += 1;
            }
        }
        assert!(ran >= 8, "only {ran} models ran from their start");
    }

    #[test]
    fn invalid_parameters_are_reported() {
        let sim = simulator("bouc_wen", 1e-3).unwrap();
        let kin = vec![Kin::default(); 4];
        let mut out = vec![0.0; 4];
        // n = 0 is outside the model's bounds.
        assert!(!sim.run(&[1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0], &kin, &mut out));
        assert!(!sim.valid(&[1.0]));
        assert!(simulator("nope", 1e-3).is_none());
    }
}
