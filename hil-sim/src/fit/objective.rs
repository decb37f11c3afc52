//! The least-squares objective every optimiser shares: run the core over the training
//! part, compare with the measurement on the rows that count.

use model_core::Kin;

use super::simulate::Simulator;
use super::spec::ModelSpec;

/// Residuals of one model on one stretch of data.
///
/// The model runs over every sample from the start of `kin` (its state must see the
/// whole history) but only `rows` (training samples not flagged by the quality checks)
/// enter the sum. Residuals are divided by `scale` (the output's spread) so that the
/// tolerances of the optimisers mean the same thing in every unit.
pub struct Objective<'a> {
    pub sim: &'a dyn Simulator,
    pub spec: &'a ModelSpec,
    pub kin: &'a [Kin],
    pub y: &'a [f64],
    pub rows: &'a [usize],
    pub scale: f64,
    /// Indices of the free parameters.
    pub free: Vec<usize>,
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
        Self { sim, spec, kin: &kin[..end], y, rows, scale: scale.max(1e-300), free: spec.free() }
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

    /// Scaled residuals at `p`, `None` when the model rejects `p` or diverges.
    pub fn residuals(&self, p: &[f64]) -> Option<Vec<f64>> {
        let mut out = vec![0.0; self.kin.len()];
        if !self.sim.run(p, self.kin, &mut out) {
            return None;
        }
        let inv = 1.0 / self.scale;
        self.rows.iter().map(|&i| Some((out.get(i)? - self.y.get(i)?) * inv)).collect()
    }

    /// Mean squared scaled residual (∞ when invalid).
    pub fn cost(&self, p: &[f64]) -> f64 {
        match self.residuals(p) {
            Some(r) if !r.is_empty() => r.iter().map(|v| v * v).sum::<f64>() / r.len() as f64,
            _ => f64::INFINITY,
        }
    }
}
