//! The least-squares objective every optimiser shares: run the core over the training
//! part, compare with the measurement on the rows that count.

use std::sync::{Arc, Mutex};

use model_core::Kin;

use super::simulate::Simulator;
use crate::models::alignment::{shift_kin_runs, MAX_DELAY_SAMPLES};
use crate::models::search::ModelSpec;

/// Shifted kinematics kept ([`Objective::shifted_by`]).
const SHIFT_CACHE: usize = 4;

/// Kinematics shifted by an (input, command) delay pair, in samples.
type ShiftedKin = ((f64, f64), Arc<Vec<Kin>>);

/// Residuals of one model on one stretch of data.
///
/// The model runs over every sample from the start of `kin` (its state must see the
/// whole history) but only `rows` (training samples not flagged by the quality checks)
/// enter the sum. When the spec carries more entries than the model has parameters, the
/// first is an input delay and the second a command delay, in samples
/// ([`crate::models::alignment`]), fitted with the rest. Residuals are divided by `scale` (the output's spread) so that the
/// tolerances of the optimisers mean the same thing in every unit.
pub struct Objective<'a> {
    pub sim: &'a dyn Simulator,
    pub spec: &'a ModelSpec,
    /// The kinematics up to the last row, plus a margin for the delay to read ahead.
    pub kin: &'a [Kin],
    /// Samples the model runs over (one past the last row).
    pub end: usize,
    pub y: &'a [f64],
    pub rows: &'a [usize],
    /// `rows` as runs ([`crate::numerics::spans`]).
    spans: crate::numerics::spans::Spans,
    pub scale: f64,
    /// Indices of the free parameters.
    pub free: Vec<usize>,
    /// The kinematics shifted by the delays last asked for (the latest first): a Jacobian's
    /// columns for the model's own parameters all share one pair of delays.
    shifted: Mutex<Vec<ShiftedKin>>,
}

impl<'a> Objective<'a> {
    pub fn new(
        sim: &'a dyn Simulator,
        spec: &'a ModelSpec,
        kin: &'a [Kin],
        y: &'a [f64],
        rows: &'a [usize],
        scale: f64,
    ) -> Self {
        let end = rows.last().map_or(0, |r| r + 1).min(kin.len());
        let ext = (end + MAX_DELAY_SAMPLES.ceil() as usize + 1).min(kin.len());
        Self {
            sim,
            spec,
            kin: &kin[..ext],
            end,
            y,
            rows,
            spans: crate::numerics::spans::Spans::of(rows),
            scale: scale.max(1e-300),
            free: spec.free(),
            shifted: Mutex::new(Vec::new()),
        }
    }

    /// The model's own parameters of a full vector `p` (without the delay entry).
    pub fn model_params<'p>(&self, p: &'p [f64]) -> &'p [f64] {
        p.get(..self.sim.n_params()).unwrap_or(p)
    }

    /// The input and command delays in samples that `p` carries (0 when the spec has none).
    pub fn delays(&self, p: &[f64]) -> (f64, f64) {
        let n = self.sim.n_params();
        (p.get(n).copied().unwrap_or(0.0), p.get(n + 1).copied().unwrap_or(0.0))
    }

    /// The full parameter vector for free-parameter positions `unit` (each in [0, 1] of its box).
    pub fn from_unit(&self, unit: &[f64]) -> Vec<f64> {
        let mut p = self.spec.start();
        for (&j, s) in self.free.iter().zip(unit) {
            if let (Some(v), Some(ps)) = (p.get_mut(j), self.spec.params.get(j)) {
                *v = ps.from_unit(*s);
            }
        }
        p
    }

    /// Box positions of the free parameters of `p`.
    pub fn to_unit(&self, p: &[f64]) -> Vec<f64> {
        self.free.iter().filter_map(|&j| Some(self.spec.params.get(j)?.to_unit(*p.get(j)?))).collect()
    }

    /// Run the model at `p` over the samples up to the last row and hand its output to `with`
    /// (`None` when the model rejects `p` or diverges). The output buffer is the thread's own,
    /// reused from one run to the next.
    fn simulate<T>(&self, p: &[f64], with: impl FnOnce(&[f64]) -> Option<T>) -> Option<T> {
        thread_local! {
            static OUT: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) };
        }
        let run = |out: &mut Vec<f64>| -> Option<T> {
            // Every simulator writes each sample it is given ([`Simulator::run`]): a buffer of
            // the right length is written over, not cleared first.
            if out.len() != self.end {
                out.clear();
                out.resize(self.end, 0.0);
            }
            let (d, d_u) = self.delays(p);
            let ok = if d == 0.0 && d_u == 0.0 {
                self.sim.run(self.model_params(p), self.kin.get(..self.end)?, out)
            } else {
                let shifted = self.shifted_by(d, d_u);
                self.sim.run(self.model_params(p), shifted.get(..self.end)?, out)
            };
            if ok {
                with(out)
            } else {
                None
            }
        };
        OUT.with(|cell| match cell.try_borrow_mut() {
            Ok(mut out) => run(&mut out),
            Err(_) => run(&mut Vec::new()),
        })
    }

    /// Scaled residuals at `p`, `None` when the model rejects `p` or diverges.
    pub fn residuals(&self, p: &[f64]) -> Option<Vec<f64>> {
        let inv = 1.0 / self.scale;
        self.simulate(p, |out| self.spans.map2(out, self.y, |o, y| (o - y) * inv))
    }

    /// The kinematics shifted by `(d, d_u)` samples, from the cache when the delays are
    /// among the last few asked for (a Jacobian's columns ask for the point's delays and
    /// for each delay stepped, concurrently).
    fn shifted_by(&self, d: f64, d_u: f64) -> Arc<Vec<Kin>> {
        if let Ok(cache) = self.shifted.lock() {
            if let Some((_, kin)) = cache.iter().find(|(key, _)| *key == (d, d_u)) {
                return Arc::clone(kin);
            }
        }
        let mut shifted = Vec::with_capacity(self.kin.len());
        shift_kin_runs(self.kin, d, d_u, self.sim.run_starts(), &mut shifted);
        let shifted = Arc::new(shifted);
        if let Ok(mut cache) = self.shifted.lock() {
            if !cache.iter().any(|(key, _)| *key == (d, d_u)) {
                cache.insert(0, ((d, d_u), Arc::clone(&shifted)));
                cache.truncate(SHIFT_CACHE);
            }
        }
        shifted
    }

    /// Mean squared scaled residual (∞ when invalid): [`crate::numerics::stats::mean_square`]
    /// of [`Objective::residuals`], summed as it sums them, without the residual vector.
    pub fn cost(&self, p: &[f64]) -> f64 {
        self.cost_of(self.simulate(p, |out| self.squares(out)))
    }

    /// [`Objective::cost`] of the residuals [`Objective::residuals`] gave (the same number).
    pub fn cost_of_residuals(&self, r: &[f64]) -> f64 {
        self.cost_of((r.len() == self.rows.len()).then(|| r.iter().map(|r| r * r).sum::<f64>()))
    }

    fn cost_of(&self, sum: Option<f64>) -> f64 {
        match sum {
            Some(s) if !self.rows.is_empty() => s / self.rows.len() as f64,
            _ => f64::INFINITY,
        }
    }

    /// The sum of the squared scaled residuals of the output `out` (`None` when a row is
    /// past its end).
    fn squares(&self, out: &[f64]) -> Option<f64> {
        let inv = 1.0 / self.scale;
        let mut bad = false;
        let s = self
            .rows
            .iter()
            .map(|&i| match (out.get(i), self.y.get(i)) {
                (Some(o), Some(y)) => {
                    let r = (o - y) * inv;
                    r * r
                }
                _ => {
                    bad = true;
                    0.0
                }
            })
            .sum::<f64>();
        (!bad).then_some(s)
    }
}
