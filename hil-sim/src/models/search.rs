//! What the optimisers search: the types of a model's search box (bounds, starting values,
//! which parameters stay fixed, which method fits the model), the recording's spreads that
//! size every box, and the default rate estimator. Each model writes its own box in its
//! host file (`models/<id>.rs`, [`super::HostModel::search`]).
//!
//! The papers publish bounds and values in their own units (mT and N·m for the clutch of
//! seed 000, cm and N for the Dyke damper, mm and kN in seed 002). A recording comes in
//! any units, so every box here is the paper's box written in the recording's own scales
//! ([`Scales`]): a force coefficient is bounded by multiples of the output's spread, a
//! damping by output spread over rate spread, and so on. Where a paper publishes a full
//! set (Spencer et al. 1997 for the Dyke damper) it is rescaled the same way and used as
//! a starting point.
//!
//! A command-dependent coefficient (`*_b`, polynomial terms in `u`) is fixed at zero when
//! the recording has no command channel: the data cannot identify it.

use serde::Serialize;

use super::RateSpec;

/// Spreads of the training data that set the size of every search box.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Scales {
    /// Mean and standard deviation of the input x.
    pub x_mean: f64,
    pub x: f64,
    /// Standard deviation of the input's rate ẋ and acceleration ẍ.
    pub dx: f64,
    pub ddx: f64,
    /// Mean and standard deviation of the output.
    pub y_mean: f64,
    pub y: f64,
    /// Largest |command|, when the recording has a command channel.
    pub u: Option<f64>,
    /// Sampling rate, Hz.
    pub fs: f64,
}

/// Bandwidth of the default rate estimator as a fraction of the sampling rate.
pub const RATE_BANDWIDTH_OF_FS: f64 = 1.0 / 60.0;

/// The default rate estimator: seed 002's steady-state Kalman filter (eq. 19–27) tuned to a
/// bandwidth of `fs/60` (50 Hz at the Dyke files' 3 kHz, inside their 100 Hz anti-aliasing
/// band; 33 Hz at 2 kHz). A constant-acceleration Kalman filter's steady-state gain depends
/// only on q/r, and its bandwidth is about (q/r)^(1/6) rad/s, so r is set to a small
/// fraction of the input's variance and q = r·ω⁶.
///
/// A plain backward difference passes the sensor's quantisation noise straight into the
/// `c·ẋ` terms (on `ranran_50.csv` this alone is an 18 N error while the damper rests).
pub fn default_rate(s: &Scales) -> RateSpec {
    let w = 2.0 * std::f64::consts::PI * s.fs * RATE_BANDWIDTH_OF_FS;
    let r = (s.x.max(1e-12) * 1e-3).powi(2);
    RateSpec::Kalman { q: (r * w.powi(6)) as f32, r: r as f32 }
}

/// How a parameter is searched between its bounds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Spacing {
    Linear,
    /// Searched on a log scale (both bounds > 0): coefficients that span decades.
    Log,
}

/// One parameter's search box.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ParamSpec {
    pub name: &'static str,
    pub lo: f64,
    pub hi: f64,
    pub start: f64,
    pub spacing: Spacing,
    /// Held at `start`.
    pub fixed: bool,
}

impl ParamSpec {
    pub fn new(name: &'static str, lo: f64, hi: f64, start: f64) -> Self {
        Self { name, lo, hi, start, spacing: Spacing::Linear, fixed: false }
    }
    pub fn log(mut self) -> Self {
        self.spacing = Spacing::Log;
        self
    }
    pub fn fixed(mut self, v: f64) -> Self {
        self.fixed = true;
        self.start = v;
        self
    }
    pub fn fixed_if(self, cond: bool, v: f64) -> Self {
        if cond {
            self.fixed(v)
        } else {
            self
        }
    }

    /// `v` if it lies in the box; otherwise just inside the nearer end (a millionth of the
    /// box in: at the end itself a bounded search's unit map has zero slope and cannot move
    /// it). A fit made in a wider box (a parameter held later) starts its refits from here.
    pub fn into_box(&self, v: f64) -> f64 {
        if self.fixed || (self.lo..=self.hi).contains(&v) || !v.is_finite() {
            return v;
        }
        let step = 1e-6 * (self.hi - self.lo);
        if v < self.lo {
            (self.lo + step).min(self.hi)
        } else {
            (self.hi - step).max(self.lo)
        }
    }

    /// Position of `v` in the box, 0 at `lo` and 1 at `hi` (clamped).
    pub fn to_unit(&self, v: f64) -> f64 {
        let s = match self.spacing {
            Spacing::Linear => (v - self.lo) / (self.hi - self.lo),
            Spacing::Log => (v.max(self.lo).ln() - self.lo.ln()) / (self.hi.ln() - self.lo.ln()),
        };
        if s.is_finite() {
            s.clamp(0.0, 1.0)
        } else {
            0.5
        }
    }

    /// The value at position `s` ∈ [0, 1] of the box.
    pub fn from_unit(&self, s: f64) -> f64 {
        let s = s.clamp(0.0, 1.0);
        match self.spacing {
            Spacing::Linear => self.lo + s * (self.hi - self.lo),
            Spacing::Log => (self.lo.ln() + s * (self.hi.ln() - self.lo.ln())).exp(),
        }
    }
}

/// Which method identifies the model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Strategy {
    /// Linear in its parameters: closed-form least squares.
    Linear,
    /// Levenberg–Marquardt from the starting values.
    Local,
    /// Particle swarm over the box, then Levenberg–Marquardt from the best candidates.
    Global,
    /// Operator model linear in its weights for fixed radii: sign-constrained least squares
    /// for a few radius spreads ([`crate::ident::fit::operator::closed_form`]).
    Operator,
    /// Particle swarm and Levenberg–Marquardt over the shape only, the output scale and
    /// offset solved in closed form at every evaluation ([`crate::ident::fit::operator::Projected`]).
    Projected,
    /// Network trained in simulation mode by Levenberg–Marquardt ([`crate::ident::fit::narx`]).
    Network,
}

/// The model-specific structure a fitting method exploits; `Generic` for a model fitted
/// through its simulator alone.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Structure {
    #[default]
    Generic,
    /// Play operators (Prandtl–Ishlinskii): weights by sign-constrained least squares.
    PlayOperators,
    /// Elasto-slide elements (Maxwell-slip): stiffnesses by sign-constrained least squares.
    ElastoSlide,
    /// Preisach: output offset and scale solved by projection.
    PreisachProjection,
    /// GPI: p₀, δ₁ and a common offset solved by projection.
    GpiProjection,
    /// NARX network (seed 000 eq. 18–19).
    Narx,
    /// Hammerstein–Wiener network (seed 000 eq. 15–17).
    HammersteinWiener,
    /// Asymmetric Bouc–Wen: the fitted loop is checked for self-crossing (seed 004 §6.2).
    AsymmetricBoucWen,
}

/// The recording's spreads with floors, as every search box uses them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spreads {
    /// Spreads of the input, its rate, its acceleration and the output (floored at 1e-12).
    pub x: f64,
    pub v: f64,
    pub a: f64,
    pub y: f64,
    /// Mean output.
    pub ym: f64,
    /// No command channel: command terms are fixed at zero.
    pub no_u: bool,
    /// Largest |command| (1 without a command channel), floored at 1e-6.
    pub u: f64,
    /// A bound for output offsets: |ȳ| + 10·σ_y.
    pub big_y: f64,
}

impl Spreads {
    pub fn of(s: &Scales) -> Self {
        let y = s.y.max(1e-12);
        Self {
            x: s.x.max(1e-12),
            v: s.dx.max(1e-12),
            a: s.ddx.max(1e-12),
            y,
            ym: s.y_mean,
            no_u: s.u.is_none(),
            u: s.u.unwrap_or(1.0).max(1e-6),
            big_y: s.y_mean.abs() + 10.0 * y,
        }
    }
}

/// A model's search box and the method that fits it, as its host file writes them.
pub type SearchBox = (Vec<ParamSpec>, Strategy);

/// Everything the fit needs to know about one model.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ModelSpec {
    pub id: &'static str,
    pub params: Vec<ParamSpec>,
    pub strategy: Strategy,
    /// Which model-specific structure the method exploits (operator columns, projection,
    /// network), as the model's host file declares it.
    #[serde(skip)]
    pub structure: Structure,
    /// Rate estimator the model is fitted and replayed with.
    #[serde(skip)]
    pub rate: RateSpec,
}

impl ModelSpec {
    /// The starting vector.
    pub fn start(&self) -> Vec<f64> {
        self.params.iter().map(|p| p.start).collect()
    }
    /// The same search with free entries after the model's parameters: an input delay and,
    /// with `command`, a command delay, in samples within ±`max_samples`, starting at 0.
    pub fn with_delays(mut self, command: bool, max_samples: f64) -> Self {
        self.params.push(ParamSpec::new("delay", -max_samples, max_samples, 0.0));
        if command {
            self.params.push(ParamSpec::new("command_delay", -max_samples, max_samples, 0.0));
        }
        self
    }
    /// Hold parameter `name` at `value` (a box of zero width).
    pub fn hold(&mut self, name: &str, value: f64) {
        if let Some(p) = self.params.iter_mut().find(|p| p.name == name) {
            *p = ParamSpec::new(p.name, value, value, value).fixed(value);
        }
    }
    /// Indices of the free parameters.
    pub fn free(&self) -> Vec<usize> {
        self.params.iter().enumerate().filter(|(_, p)| !p.fixed).map(|(i, _)| i).collect()
    }
}

/// The box of a network model (seed 000 eq. 15–19): one wide entry per weight, named as
/// the registry names the block (`w[12]` is twelve entries named `w[12]`).
pub fn network_layout(names: &[&'static str], n_params: usize) -> Vec<ParamSpec> {
    let mut ps = Vec::with_capacity(n_params);
    for &name in names {
        let len = name.split_once('[').and_then(|(_, r)| r.trim_end_matches(']').parse().ok()).unwrap_or(1);
        ps.extend((0..len).map(|_| ParamSpec::new(name, -1e6, 1e6, 0.0)));
    }
    ps
}

/// A published value that model-core stores as f32, as the paper prints it: the shortest
/// decimal that reads back to the same f32 (46.9, not 46.900001525878906).
pub fn published(v: f32) -> f64 {
    v.to_string().parse().unwrap_or(f64::from(v))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A value outside the box starts just inside its nearer end, where a bounded search can
    /// move it; inside, fixed or not finite, it is left as it is.
    #[test]
    fn a_value_outside_the_box_starts_just_inside_it() {
        let p = ParamSpec::new("alpha", 0.0, 100.0, 1.0);
        let near = |a: f64, b: f64| (a - b).abs() < 1e-12;
        assert!(near(p.into_box(-22.1), 1e-4), "{}", p.into_box(-22.1));
        assert!(near(p.into_box(250.0), 100.0 - 1e-4), "{}", p.into_box(250.0));
        assert_eq!(p.into_box(3.0), 3.0);
        assert_eq!(p.into_box(0.0), 0.0);
        assert!(p.into_box(f64::NAN).is_nan());
        assert_eq!(ParamSpec::new("n", 1.0, 3.0, 2.0).fixed(5.0).into_box(5.0), 5.0);
        // Where the unit map's slope is zero (the box's end) the value is not put.
        assert!(p.to_unit(p.into_box(-1.0)) > 0.0);
    }
}
